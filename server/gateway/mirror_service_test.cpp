// A device node behind a gateway node: forwarding, fan-out, callbacks and device restarts, at the entry
// level with RawClient as the downstream client.
#include <catch2/catch.hpp>

#include <atomic>
#include <future>
#include <thread>

#include "server/client/raw_client.hpp"
#include "server/gateway/device_mirror.hpp"
#include "server/node/node.hpp"
#include "server/node/test_node.hpp"
#include "server/service/test_raw_service.hpp"
#include "server/transport/tcp_listener.hpp"
#include "test/support/eventually.hpp"

using namespace rr;
using namespace rr::server;
using namespace rr::server::gateway;
using namespace std::chrono_literals;
using rr::server::testing::RawTestService;
using rr::server::testing::test_node;

namespace {

struct Device {
    std::shared_ptr<Node> node;
    std::shared_ptr<RawTestService> service = std::make_shared<RawTestService>();
    std::uint16_t port = 0;

    explicit Device(std::uint16_t want_port = 0) {
        node = test_node("device.node");
        REQUIRE(node->register_service(service));
        auto p = listen_tcp(node, "127.0.0.1", want_port);
        REQUIRE(p);
        port = *p;
    }
};

struct Gateway {
    std::shared_ptr<Node> node = test_node("gateway.node");
    std::shared_ptr<DeviceMirror> mirror;
    std::uint16_t port = 0;

    explicit Gateway(std::uint16_t device_port, std::function<void(DeviceConfig&)> tweak = {}) {
        DeviceConfig cfg;
        cfg.name = "dev";
        cfg.url = "rr+tcp://127.0.0.1:" + std::to_string(device_port) + "/?service=svc";
        cfg.backoff_initial = 100ms;
        cfg.backoff_max = 400ms;
        if (tweak) tweak(cfg);
        auto m = DeviceMirror::create(node, cfg);
        REQUIRE(m);
        mirror = *m;
        mirror->start();
        port = *listen_tcp(node, "127.0.0.1", 0);
    }
    ~Gateway() {
        mirror->stop();
        node->shutdown();
    }

    bool wait_state(DeviceState s, std::chrono::milliseconds timeout = rr::testing::kHangBound) {
        auto until = std::chrono::steady_clock::now() + timeout;
        while (std::chrono::steady_clock::now() < until) {
            if (mirror->status().state == s) return true;
            std::this_thread::sleep_for(10ms);
        }
        return false;
    }

    Result<std::shared_ptr<RawClient>> try_connect(RawClient::IncomingHandler incoming = {}) {
        std::promise<Result<std::shared_ptr<RawClient>>> p;
        auto url = parse_connection_url("rr+tcp://127.0.0.1:" + std::to_string(port) + "/?service=dev");
        RawClient::connect(node->io_context().get_executor(), *url, {}, std::move(incoming), {},
                           [&](Result<std::shared_ptr<RawClient>> r) { p.set_value(std::move(r)); });
        return p.get_future().get();
    }
    std::shared_ptr<RawClient> connect(RawClient::IncomingHandler incoming = {}) {
        auto r = try_connect(std::move(incoming));
        REQUIRE(r);
        return *r;
    }
};

Result<MessageEntry> call(RawClient& c, MessageEntry e) {
    std::promise<Result<MessageEntry>> p;
    c.request(std::move(e), [&](Result<MessageEntry> r) { p.set_value(std::move(r)); });
    return p.get_future().get();
}

MessageEntry request(MessageEntryType type, std::string member, std::string path = "dev") {
    MessageEntry e;
    e.entry_type = type;
    e.service_path = std::move(path);
    e.member_name = std::move(member);
    return e;
}

double scalar(const MessageEntry& e, const char* name) {
    double v = -1;
    if (const auto* el = e.find(name)) read_scalar(*el, v);
    return v;
}

}  // namespace

TEST_CASE("the gateway re-hosts a device under its own name") {
    Device device;
    Gateway gw(device.port);
    REQUIRE(gw.wait_state(DeviceState::connected));
    auto c = gw.connect();
    CHECK(c->info().object_type == "example.rawtest.Obj");
    REQUIRE(c->info().service_definitions.size() == 1);

    auto get = call(*c, request(MessageEntryType::PropertyGetReq, "x"));
    REQUIRE(get);
    CHECK(get->service_path == "dev");
    CHECK(scalar(*get, "value") == 42.5);

    auto bad = call(*c, request(MessageEntryType::FunctionCallReq, "nosuch"));
    REQUIRE(bad);
    CHECK(bad->error == MessageErrorType::MemberNotFound);

    auto status = gw.mirror->status();
    CHECK(status.state == DeviceState::connected);
    CHECK(status.downstream_sessions == 1);
    CHECK(gw.mirror->counters().requests.load() >= 2);
}

TEST_CASE("a device counts as connected only once its service is registered on the gateway node") {
    // /readyz and Gateway::ready() poll status(): a client that waited for "connected" must find the service.
    Device device;
    auto node = test_node("gateway.node");
    DeviceConfig cfg;
    cfg.name = "dev";
    cfg.url = "rr+tcp://127.0.0.1:" + std::to_string(device.port) + "/?service=svc";
    auto m = DeviceMirror::create(node, cfg);
    REQUIRE(m);
    std::atomic<int> registrations{0};
    std::atomic<bool> connected_before_registered{false};
    node->on_services_changed([&, mirror = std::weak_ptr<DeviceMirror>(*m)] {
        auto self = mirror.lock();
        if (!self || !node->find_service("dev")) return;
        ++registrations;
        if (self->status().state == DeviceState::connected) connected_before_registered = true;
    });
    (*m)->start();
    CHECK(rr::testing::eventually([&] { return (*m)->status().state == DeviceState::connected; }));
    CHECK(registrations.load() == 1);
    CHECK_FALSE(connected_before_registered.load());
    (*m)->stop();
    node->shutdown();
}

TEST_CASE("events and wire values fan out to every client, callbacks go to the caller") {
    Device device;
    Gateway gw(device.port);
    REQUIRE(gw.wait_state(DeviceState::connected));

    struct Seen {
        std::mutex m;
        int events = 0, wires = 0;
        double last_wire = 0;
    };
    std::vector<std::shared_ptr<Seen>> seen;
    std::vector<std::shared_ptr<RawClient>> clients;
    std::vector<std::weak_ptr<RawClient>> weak(3);
    for (int i = 0; i < 3; ++i) {
        auto s = std::make_shared<Seen>();
        seen.push_back(s);
        auto* slot = &weak[i];
        clients.push_back(gw.connect([s, slot, i](MessageEntry&& e) {
            std::lock_guard lock(s->m);
            if (e.entry_type == MessageEntryType::EventReq) ++s->events;
            if (e.entry_type == MessageEntryType::WirePacket) {
                ++s->wires;
                s->last_wire = scalar(e, "packet");
            }
            if (e.entry_type == MessageEntryType::CallbackCallReq) {
                MessageEntry r;
                r.entry_type = MessageEntryType::CallbackCallRet;
                r.service_path = e.service_path;
                r.member_name = e.member_name;
                r.request_id = e.request_id;
                r.elements.push_back(make_scalar_element("return", scalar(e, "v") + 100.0 * i));
                if (auto c = slot->lock()) c->send(std::move(r));
            }
        }));
        weak[i] = clients.back();
    }
    // Clients 0 and 1 connect the wire: one upstream connection serves both.
    for (int i = 0; i < 2; ++i) {
        auto r = call(*clients[i], request(MessageEntryType::WireConnectReq, "w"));
        REQUIRE(r);
        CHECK(r->error == MessageErrorType::None);
    }
    {
        std::lock_guard lock(device.service->mutex);
        CHECK(device.service->wire_sessions.size() == 1);
    }
    REQUIRE(call(*clients[2], request(MessageEntryType::FunctionCallReq, "fire")));
    auto until = std::chrono::steady_clock::now() + rr::testing::kHangBound;
    auto done = [&] {
        for (int i = 0; i < 3; ++i) {
            std::lock_guard lock(seen[i]->m);
            if (seen[i]->events < 1) return false;
            if (i < 2 && seen[i]->wires < 1) return false;
        }
        return true;
    };
    while (!done() && std::chrono::steady_clock::now() < until) std::this_thread::sleep_for(10ms);
    REQUIRE(done());
    {
        std::lock_guard lock(seen[2]->m);
        CHECK(seen[2]->wires == 0);  // not connected to the wire
    }
    CHECK(seen[0]->last_wire == 9.5);

    // The device calls back the gateway; the gateway routes to the client that called `callme`.
    auto callme = request(MessageEntryType::FunctionCallReq, "callme");
    callme.elements.push_back(make_scalar_element("v", 1.0));
    auto r = call(*clients[1], std::move(callme));
    REQUIRE(r);
    CHECK(r->error == MessageErrorType::None);
    CHECK(scalar(*r, "return") == 101.0);
}

TEST_CASE("a device that restarts: errors while it is gone, then everything works again") {
    auto device = std::make_unique<Device>();
    const auto port = device->port;
    Gateway gw(port);
    REQUIRE(gw.wait_state(DeviceState::connected));
    auto c = gw.connect();
    REQUIRE(call(*c, request(MessageEntryType::WireConnectReq, "w")));
    REQUIRE(call(*c, request(MessageEntryType::PropertyGetReq, "x")));

    device->node->shutdown();
    device.reset();
    REQUIRE(gw.wait_state(DeviceState::failed));
    auto gone = call(*c, request(MessageEntryType::PropertyGetReq, "x"));
    REQUIRE(gone);
    CHECK(gone->error == MessageErrorType::ConnectionError);
    CHECK(entry_error(*gone)->message.find("not connected") != std::string::npos);
    CHECK_FALSE(gw.mirror->status().reason.empty());

    device = std::make_unique<Device>(port);
    REQUIRE(gw.wait_state(DeviceState::connected));
    auto back = call(*c, request(MessageEntryType::PropertyGetReq, "x"));
    REQUIRE(back);
    CHECK(back->error == MessageErrorType::None);
    CHECK(scalar(*back, "value") == 42.5);
    // The downstream wire connection survived and was re-subscribed upstream.
    auto until = std::chrono::steady_clock::now() + rr::testing::kHangBound;
    std::size_t n = 0;
    while (std::chrono::steady_clock::now() < until) {
        {
            std::lock_guard lock(device->service->mutex);
            n = device->service->wire_sessions.size();
        }
        if (n == 1) break;
        std::this_thread::sleep_for(10ms);
    }
    CHECK(n == 1);
    CHECK(gw.mirror->counters().reconnects.load() == 1);
}

TEST_CASE("auth: passthrough: one upstream session per client, bounded, closed with the client") {
    Device device;
    Gateway gw(device.port, [](DeviceConfig& c) {
        c.auth = DeviceAuth::passthrough;
        c.max_passthrough_sessions = 2;
    });
    REQUIRE(gw.wait_state(DeviceState::connected));
    const int shared_sessions = device.service->opened.load();  // the gateway's own session
    auto a = gw.connect();
    auto b = gw.connect();
    CHECK(device.service->opened.load() == shared_sessions + 2);
    CHECK(gw.mirror->status().upstream_sessions == 2);
    CHECK(gw.mirror->status().auth == DeviceAuth::passthrough);

    auto refused = gw.try_connect();
    REQUIRE_FALSE(refused);
    CHECK(refused.error().type == MessageErrorType::BufferLimitViolation);
    CHECK_THAT(refused.error().message, Catch::Contains("passthrough session limit (2 upstream sessions) reached"));

    // Each client's callbacks come back on its own session: b's callme calls b, not a.
    std::atomic<int> a_called{0};
    auto cb_answer = [](std::shared_ptr<RawClient>* self, std::atomic<int>* counter, double factor) {
        return [self, counter, factor](MessageEntry&& e) {
            if (e.entry_type != MessageEntryType::CallbackCallReq) return;
            if (counter) counter->fetch_add(1);
            double v = 0;
            if (const auto* el = e.find("v")) read_scalar(*el, v);
            MessageEntry r;
            r.entry_type = MessageEntryType::CallbackCallRet;
            r.service_path = e.service_path;
            r.member_name = e.member_name;
            r.request_id = e.request_id;
            r.elements.push_back(make_scalar_element<double>("return", v * factor));
            (*self)->send(std::move(r));
        };
    };
    std::shared_ptr<RawClient> c;
    a->close();
    a.reset();
    CHECK(rr::testing::eventually([&] { return gw.mirror->status().upstream_sessions == 1; }));
    CHECK(rr::testing::eventually([&] { return device.service->closed.load() >= 1; }));
    CHECK(device.service->closed.load() == 1);  // a's upstream session went with a
    auto r = gw.try_connect(cb_answer(&c, &a_called, 3.0));
    REQUIRE(r);
    c = *r;
    auto fn = request(MessageEntryType::FunctionCallReq, "callme");
    fn.elements.push_back(make_scalar_element<double>("v", 2.0));
    auto ret = call(*c, std::move(fn));
    REQUIRE(ret);
    CHECK(ret->error == MessageErrorType::None);
    CHECK(scalar(*ret, "return") == 6.0);  // this client's callback (v * 3)
    CHECK(a_called.load() == 1);
    c->close();
    b->close();
}
