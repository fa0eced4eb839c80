// Test and benchmark fixture: an emulated RR USB device (usb_emulator.hpp) serving a node with the
// demo services (create, webcam) and `usbtest` (example.usbtest: nop, echo, a generator, a call that
// answers only when released), and a UsbHost on the real libusb reaching it through rr+usb.
#pragma once

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "server/client/client.hpp"
#include "server/demo/demo_devices.hpp"
#include "server/service/object_service.hpp"
#include "server/service/service_types.hpp"
#include "server/transport/usb/usb_host.hpp"
#include "server/transport/usb/usb_libusb.hpp"
#include "test/support/eventually.hpp"
#include "test/usb/usb_emulator.hpp"

namespace rr::test::usb {

inline constexpr const char* kUsbTestDef = R"(service example.usbtest

stdver 0.10

object Bench
    function void nop()
    function uint8[] echo(uint8[] data)
    function int32{generator} count(int32 n)
    function double slow(double x)
    property uint8[] blob
end
)";

inline const NodeID& device_node_id() {
    static const NodeID id = NodeID::parse("{5a3c9d2e-7b41-4c8a-9e0f-31d2c4b5a6e7}").value();
    return id;
}
inline constexpr const char* kDeviceNodeName = "usb_demo";

/// Calls of `slow` waiting for release().
class SlowCalls {
public:
    void add(server::Completion done) {
        std::lock_guard lock(m_);
        waiting_.push_back(std::move(done));
        cv_.notify_all();
    }
    bool wait_for_call(std::chrono::milliseconds t) {
        std::unique_lock lock(m_);
        return cv_.wait_for(lock, t, [&] { return !waiting_.empty(); });
    }
    void release(double v) {
        std::vector<server::Completion> w;
        {
            std::lock_guard lock(m_);
            w.swap(waiting_);
        }
        for (auto& d : w) d(Value::scalar(v));
    }

private:
    std::mutex m_;
    std::condition_variable cv_;
    std::vector<server::Completion> waiting_;
};

struct WorldOptions {
    bool demo = true;
    server::usb::UsbHostOptions host;
    unsigned device_threads = 2;
    unsigned client_threads = 2;
};

class UsbWorld {
public:
    /// Errors: the emulator's (NotImplementedError outside umockdev), setup errors.
    static Result<std::unique_ptr<UsbWorld>> create(WorldOptions options = {}) {
        auto emu = UsbEmulator::create();
        if (!emu) return emu.take_error();
        std::unique_ptr<UsbWorld> w(new UsbWorld(options));
        w->emulator = std::move(*emu);
        server::NodeOptions no;
        no.node_id = device_node_id();
        no.node_name = kDeviceNodeName;
        no.threads = options.device_threads;
        w->node = server::Node::create(no);
        if (options.demo) {
            server::demo::DemoOptions demo_opts;
            auto d = server::demo::make_demo_devices(demo_opts);
            if (!d) return d.take_error();
            w->demo = std::move(*d);
            if (auto r = w->node->register_service(w->demo.create_service); !r) return r.take_error();
            if (auto r = w->node->register_service(w->demo.webcam_service); !r) return r.take_error();
        }
        if (auto r = w->add_test_service(); !r) return r.take_error();
        return w;
    }

    /// The default device: the node's NodeID and NodeName, BOS capability in sysfs, 512-byte packets.
    static EmulatedDeviceOptions device_options(std::uint8_t address = 2) {
        EmulatedDeviceOptions o;
        o.strings.node_id = device_node_id();
        o.strings.node_name = kDeviceNodeName;
        o.address = address;
        return o;
    }

    Result<EmulatedDevice*> plug(EmulatedDeviceOptions o = device_options()) { return emulator->plug(std::move(o), node); }

    /// Starts the host transport (after plugging, so the first scan finds the devices).
    Result<void> start_host() {
        // An earlier world's libusb context still open would keep libusb's hotplug monitor on that
        // world's (removed) umockdev testbed: this world's devices would never be listed.
        if (!rr::testing::eventually([] { return server::usb::LibusbContext::open_contexts() == 0; }))
            return fail(MessageErrorType::InvalidOperation, "a libusb context of an earlier USB world is still open");
        if (std::getenv("RR_USB_DEBUG"))
            options_.host.log = [](std::string_view line) { std::fprintf(stderr, "usb host: %.*s\n", int(line.size()), line.data()); };
        auto h = server::usb::UsbHost::create(io.executor(), options_.host);
        if (!h) return h.take_error();
        host = *h;
        server::usb::register_usb_transport(server::default_transports(), host);
        return {};
    }

    std::string url(std::string_view service) const {
        return std::string("rr+usb:///?nodename=") + kDeviceNodeName + "&service=" + std::string(service);
    }
    Result<std::shared_ptr<client::Client>> connect(std::string_view service, client::ClientOptions o = {}) {
        return client::Client::connect(io.executor(), url(service), o);
    }

    ~UsbWorld() {
        if (host) {
            host->shutdown();
            rr::testing::eventually([&] { return host->idle(); });
            // Probes and links in flight hold the host, and with it the libusb context, until their
            // transfers end: the emulator must answer until then (a transfer left to a gone emulator
            // never ends, or aborts umockdev's preload), and the context must be exited before the
            // next world's is made (start_host()).
            std::weak_ptr<server::usb::UsbHost> gone = host;
            host.reset();
            if (!rr::testing::eventually([&] { return gone.expired(); }))
                std::fprintf(stderr, "usb world: the USB host still in use after shutdown\n");
        }
        if (!rr::testing::eventually([] { return server::usb::LibusbContext::open_contexts() == 0; }))
            std::fprintf(stderr, "usb world: a libusb context is still open\n");
        node->shutdown();
        if (demo.create_service) demo.create_service->shutdown();
        if (demo.webcam_service) demo.webcam_service->shutdown();
        if (test_service) test_service->shutdown();
        emulator.reset();
    }

    std::unique_ptr<UsbEmulator> emulator;
    std::shared_ptr<server::Node> node;
    server::demo::DemoDevices demo;
    std::shared_ptr<server::ObjectService> test_service;
    std::shared_ptr<SlowCalls> slow = std::make_shared<SlowCalls>();
    client::IoThreads io;
    std::shared_ptr<server::usb::UsbHost> host;

private:
    explicit UsbWorld(WorldOptions o) : io(o.client_threads), options_(std::move(o)) {}

    Result<void> add_test_service() {
        auto types = server::ServiceTypes::create({kUsbTestDef});
        if (!types) return types.take_error();
        auto root = server::ServiceObject::create(*types, "example.usbtest.Bench");
        if (!root) return root.take_error();
        auto& o = **root;
        if (auto r = o.set_function("nop", [](const server::SessionRef&, std::vector<Value>) -> Result<Value> { return Value(); }); !r) return r;
        if (auto r = o.set_function("echo", [](const server::SessionRef&, std::vector<Value> a) -> Result<Value> { return std::move(a.at(0)); }); !r)
            return r;
        if (auto r = o.set_generator_function(
                "count",
                [](const server::SessionRef&, std::vector<Value> a) -> Result<std::shared_ptr<server::Generator>> {
                    auto nv = a.at(0).as<std::int32_t>();
                    const std::int32_t n = nv ? *nv : 0;
                    auto i = std::make_shared<std::int32_t>(0);
                    return std::shared_ptr<server::Generator>(std::make_shared<server::FunctionGenerator>(
                        [n, i](std::optional<Value>) -> Result<Value> {
                            if (*i >= n) return fail(MessageErrorType::StopIteration, "done");
                            return Value::scalar((*i)++);
                        }));
                });
            !r)
            return r;
        std::weak_ptr<SlowCalls> weak = slow;
        if (auto r = o.set_async_function("slow",
                                          [weak](const server::SessionRef&, std::vector<Value>, server::Completion done) {
                                              if (auto s = weak.lock()) s->add(std::move(done));
                                          });
            !r)
            return r;
        auto svc = server::ObjectService::create("usbtest", *root);
        if (!svc) return svc.take_error();
        test_service = *svc;
        return node->register_service(test_service);
    }

    WorldOptions options_;
};

}  // namespace rr::test::usb
