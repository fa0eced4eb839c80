// rr_bench_usb: Nop and Echo over rr+usb through the real libusb against the umockdev-emulated device
// (test/usb/usb_emulator.hpp), next to the same calls over rr+tcp loopback to the same node in the same
// process, so that the difference is the USB transport's own cost (sub-packet framing, libusb, usbdevfs
// ioctls – here answered by umockdev over a Unix socket, a cost real hardware replaces with the bus).
// Row `floor`/`usb_control`: one bare control transfer through libusb and umockdev (no RR), the
// emulated path's floor. Labels: "ours->ours rr+usb", "ours->ours rr+tcp in-process".
// Prints one JSON line per row (bench_common.hpp: latency_row); figures only, nothing is asserted.
//
// Usage: rr_bench_usb [--count N] [--packet BYTES]
//   N: Nop calls per row (default 2000); Echo 1,000 uses N/2, Echo 100,000 N/50 (at least 10).
//   BYTES: wMaxPacketSize of the emulated bulk endpoints (default 512, USB 2.0 high speed).
// Needs umockdev: the program re-runs itself under umockdev-wrapper when it can.
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <iostream>
#include <iterator>

#include <libusb.h>

#include "bench/bench_common.hpp"
#include "server/transport/tcp_listener.hpp"
#include "test/usb/usb_world.hpp"

using namespace rr;
using namespace std::chrono_literals;
using clock_type = std::chrono::steady_clock;

namespace {

[[noreturn]] void die(const std::string& what) {
    std::cerr << "[bench_usb] " << what << std::endl;
    std::exit(1);
}

template <class T>
T must(Result<T> r, const std::string& what) {
    if (!r) die(what + ": " + r.error().message);
    return std::move(*r);
}
void must(Result<void> r, const std::string& what) {
    if (!r) die(what + ": " + r.error().message);
}

Value doubles(std::size_t n) {
    std::vector<double> v(n);
    for (std::size_t i = 0; i < n; ++i) v[i] = double(i) * 0.5;
    return Value(NumericArray::from<double>(std::span<const double>(v)));
}

template <class Fn>
void timed(const std::string& label, const std::string& op, std::size_t count, double bytes_per_op, Fn fn) {
    for (std::size_t i = 0; i < std::min<std::size_t>(20, count); ++i) fn();
    std::vector<double> samples;
    samples.reserve(count);
    const auto cpu0 = bench::CpuSnapshot::now();
    const auto t0 = clock_type::now();
    for (std::size_t i = 0; i < count; ++i) {
        const auto a = clock_type::now();
        fn();
        samples.push_back(bench::elapsed_us(a, clock_type::now()));
    }
    auto row = bench::latency_row(op, samples, bench::elapsed_us(t0, clock_type::now()), bytes_per_op, cpu0, bench::CpuSnapshot::now());
    row["label"] = label;
    std::cout << row.dump() << std::endl;
}

void run_rows(const std::string& label, const std::shared_ptr<client::Client>& c, std::size_t count) {
    auto root = c->root();
    timed(label, "nop", count, 0, [&] { must(root.call("Nop"), "Nop"); });
    for (std::size_t n : {std::size_t{10}, std::size_t{1000}, std::size_t{100000}}) {
        const auto d = doubles(n);
        const std::size_t k = n == 10 ? count : n == 1000 ? std::max<std::size_t>(count / 2, 10) : std::max<std::size_t>(count / 50, 10);
        timed(label, "echo" + std::to_string(n), k, 2.0 * 8.0 * double(n), [&] { must(root.call("Echo", {d}), "Echo"); });
    }
}

}  // namespace

int main(int argc, char** argv) {
    std::size_t count = 2000;
    std::uint16_t packet = 512;
    for (int i = 1; i + 1 < argc; i += 2) {
        const std::string a = argv[i];
        if (a == "--count") count = std::stoul(argv[i + 1]);
        else if (a == "--packet") packet = static_cast<std::uint16_t>(std::stoul(argv[i + 1]));
        else die("unknown option " + a);
    }
    if (!test::usb::emulator_unavailable_reason().empty()) {
        if (!std::getenv("RR_BENCH_USB_WRAPPED")) {  // re-run under umockdev-wrapper once
            setenv("RR_BENCH_USB_WRAPPED", "1", 1);
            std::vector<char*> args{const_cast<char*>("umockdev-wrapper")};
            for (int i = 0; i < argc; ++i) args.push_back(argv[i]);
            args.push_back(nullptr);
            execvp("umockdev-wrapper", args.data());
        }
        std::cerr << "[bench_usb] skipped: " << test::usb::emulator_unavailable_reason() << std::endl;
        return 0;
    }
    if (packet < 16 || packet > 16384) die("--packet must be 16 … 16384");

    test::usb::WorldOptions wo;
    wo.demo = false;
    auto world = must(test::usb::UsbWorld::create(wo), "emulated world");
    std::ifstream f(RR_BENCH_ROBDEF);
    const std::string def{std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
    auto types = must(server::ServiceTypes::create({def}), "experimental.bench robdef");
    auto root = must(server::ServiceObject::create(types, "experimental.bench.Bench"), "Bench object");
    must(root->set_function("Nop", [](const server::SessionRef&, std::vector<Value>) -> Result<Value> { return Value(); }), "Nop");
    must(root->set_function("Echo", [](const server::SessionRef&, std::vector<Value> a) -> Result<Value> { return std::move(a.at(0)); }),
         "Echo");
    auto service = must(server::ObjectService::create("bench", root), "bench service");
    must(world->node->register_service(service), "register bench");
    const auto port = must(listen_tcp(world->node, "127.0.0.1", 0), "listen");

    auto dev = test::usb::UsbWorld::device_options();
    dev.layout.max_packet_size = packet;
    auto* device = must(world->plug(dev), "plug");
    must(world->start_host(), "USB host");

    {
        // The floor of the emulated path: one synchronous control transfer (GET_DESCRIPTOR) through
        // libusb and umockdev, no RR. A Nop over rr+usb takes one bulk OUT and one bulk IN transfer.
        libusb_context* ctx = nullptr;
        if (libusb_init(&ctx) != 0) die("libusb_init");
        libusb_device_handle* h = libusb_open_device_with_vid_pid(ctx, dev.layout.vendor_id, dev.layout.product_id);
        if (!h) die("libusb_open_device_with_vid_pid");
        unsigned char desc[18];
        timed("floor", "usb_control", count, 0, [&] {
            if (libusb_get_descriptor(h, LIBUSB_DT_DEVICE, 0, desc, sizeof desc) != 18) die("GET_DESCRIPTOR");
        });
        libusb_close(h);
        libusb_exit(ctx);
    }
    {
        auto usb = must(world->connect("bench"), "rr+usb connect");
        run_rows(packet == 512 ? std::string("ours->ours rr+usb") : "ours->ours rr+usb " + std::to_string(packet) + " B", usb, count);
        std::cerr << "[bench_usb] bulk transfers: " << device->stats().bulk_out << " out, " << device->stats().bulk_in
                  << " in; control requests " << device->stats().control_requests << std::endl;
        (void)usb->close_wait();
    }
    {
        auto tcp = must(client::Client::connect(world->io.executor(), "rr+tcp://127.0.0.1:" + std::to_string(port) + "/?service=bench"),
                        "rr+tcp connect");
        run_rows("ours->ours rr+tcp in-process", tcp, count);
        (void)tcp->close_wait();
    }
    service->shutdown();
    return 0;
}
