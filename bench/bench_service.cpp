// rr_bench_service: serves experimental.bench (bench/experimental.bench.robdef) with our node and
// ObjectService. Handlers do no work, so a client measures transport, codec and dispatch.
//
// Usage:
//   rr_bench_service [--port N] [--websocket] [--local] [--threads N] [--memory-mib M] [--tick-hz H] [--tick-size S]
//                    [--frame-hz H] [--frame-bytes B]
//     --tick-hz H   send on the Ticks wire at H Hz from start-up until exit (fan-out benchmarks)
//     --frame-hz H  send B-byte frames (default 921,600: 640x480 RGB) on the Frames wire at H Hz until exit
//     --local       also serve rr+local, by NodeID (no NodeName)
// Prints one JSON line when ready: {"url": "rr+tcp://127.0.0.1:PORT/?service=bench", "port": PORT,
// "ws_url": … (with --websocket), "local_url": … (with --local), "pid": PID}, then runs until SIGTERM / SIGINT.
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstring>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <sstream>
#include <thread>

#include <unistd.h>

#include <nlohmann/json.hpp>

#include "bench/bench_common.hpp"
#include "server/http/http_server.hpp"
#include "server/node/node.hpp"
#include "server/service/memory_member.hpp"
#include "server/service/object_service.hpp"
#include "server/service/pipe_member.hpp"
#include "server/service/wire_member.hpp"
#include "server/transport/local/local_listener.hpp"
#include "server/transport/tcp_listener.hpp"

using namespace rr;
using namespace rr::server;

namespace {

volatile std::sig_atomic_t g_stop = 0;

template <class T>
T must(Result<T> r, const char* what) {
    if (!r) {
        std::cerr << "[bench_service] " << what << ": " << r.error().message << std::endl;
        std::exit(2);
    }
    return std::move(*r);
}
void must(Result<void> r, const char* what) {
    if (!r) {
        std::cerr << "[bench_service] " << what << ": " << r.error().message << std::endl;
        std::exit(2);
    }
}

/// Sends `count` values on the wire at `rate_hz` (0: back to back); each value is
/// [stamp_us, sequence, 0...] with `size` doubles in all. Stops early when `stop` is set.
void send_ticks(WireMember& wire, double rate_hz, std::int64_t count, std::size_t size, const std::atomic<bool>& stop) {
    using clock = std::chrono::steady_clock;
    const auto start = clock::now();
    std::vector<double> v(std::max<std::size_t>(size, 2), 0.0);
    for (std::int64_t i = 0; (count < 0 || i < count) && !stop.load() && !g_stop; ++i) {
        if (rate_hz > 0) std::this_thread::sleep_until(start + std::chrono::duration<double>(double(i) / rate_hz));
        v[0] = bench::wall_clock_us();
        v[1] = double(i);
        (void)wire.set_out_value(Value(NumericArray::from<double>(std::span<const double>(v))));
    }
}

/// Sends frames of `bytes` bytes on the wire at `rate_hz` until stopped; bytes 0-15 hold [stamp_us, sequence]
/// as doubles (the host is little-endian, as the robdef says).
void send_frames(WireMember& wire, double rate_hz, std::size_t bytes, const std::atomic<bool>& stop) {
    using clock = std::chrono::steady_clock;
    const auto start = clock::now();
    std::vector<std::uint8_t> frame(std::max<std::size_t>(bytes, 16));
    for (std::size_t i = 16; i < frame.size(); ++i) frame[i] = static_cast<std::uint8_t>(i * 7);
    for (std::int64_t i = 0; !stop.load() && !g_stop; ++i) {
        std::this_thread::sleep_until(start + std::chrono::duration<double>(double(i) / rate_hz));
        const double head[2] = {bench::wall_clock_us(), double(i)};
        std::memcpy(frame.data(), head, sizeof head);
        (void)wire.set_out_value(Value(NumericArray::from<std::uint8_t>(std::span<const std::uint8_t>(frame))));
    }
}

}  // namespace

int main(int argc, char** argv) {
    std::uint16_t port = 0;
    bool websocket = false;
    bool local = false;
    unsigned threads = 0;
    double memory_mib = 10, tick_hz = 0, frame_hz = 0;
    int tick_size = 2;
    std::size_t frame_bytes = 640 * 480 * 3;
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        auto value = [&]() -> std::string {
            if (i + 1 >= argc) {
                std::cerr << "missing value for " << a << "\n";
                std::exit(2);
            }
            return argv[++i];
        };
        if (a == "--port") port = static_cast<std::uint16_t>(std::stoi(value()));
        else if (a == "--websocket") websocket = true;
        else if (a == "--local") local = true;
        else if (a == "--threads") threads = static_cast<unsigned>(std::stoi(value()));
        else if (a == "--memory-mib") memory_mib = std::stod(value());
        else if (a == "--tick-hz") tick_hz = std::stod(value());
        else if (a == "--tick-size") tick_size = std::stoi(value());
        else if (a == "--frame-hz") frame_hz = std::stod(value());
        else if (a == "--frame-bytes") frame_bytes = std::stoul(value());
        else {
            std::cerr << "usage: " << argv[0]
                      << " [--port N] [--websocket] [--local] [--threads N] [--memory-mib M] [--tick-hz H] [--tick-size S]"
                         " [--frame-hz H] [--frame-bytes B]\n";
            return 2;
        }
    }

    struct sigaction sa {};
    sa.sa_handler = [](int) { g_stop = 1; };
    sigemptyset(&sa.sa_mask);
    sigaction(SIGTERM, &sa, nullptr);
    sigaction(SIGINT, &sa, nullptr);

    std::ifstream in(RR_BENCH_ROBDEF);
    if (!in) {
        std::cerr << "[bench_service] cannot read " << RR_BENCH_ROBDEF << std::endl;
        return 2;
    }
    std::stringstream text;
    text << in.rdbuf();
    auto types = must(ServiceTypes::create({text.str()}), "robdef");
    auto root = must(ServiceObject::create(types, "experimental.bench.Bench"), "Bench");

    must(root->set_function("Nop", [](const SessionRef&, std::vector<Value>) -> Result<Value> { return Value(); }), "Nop");
    must(root->set_function("Echo", [](const SessionRef&, std::vector<Value> a) -> Result<Value> { return std::move(a[0]); }),
         "Echo");
    must(root->set_property_value("Value", Value::scalar<double>(0.0)), "Value");
    auto ticks = must(root->wire("Ticks"), "Ticks");
    must(ticks->set_out_value(Value(NumericArray::from<double>({0.0, -1.0}))), "Ticks initial");
    auto frames = must(root->wire("Frames"), "Frames");
    {
        const double head[2] = {0.0, -1.0};  // sequence -1: no frame yet
        std::uint8_t bytes[16];
        std::memcpy(bytes, head, sizeof bytes);
        must(frames->set_out_value(Value(NumericArray::from<std::uint8_t>(std::span<const std::uint8_t>(bytes)))), "Frames initial");
    }
    std::atomic<bool> stopping{false};
    std::vector<std::thread> senders;
    std::mutex senders_mutex;
    WireMember* ticks_raw = ticks.get();
    must(root->set_function("StartTicks",
                            [&](const SessionRef&, std::vector<Value> a) -> Result<Value> {
                                const double hz = *a[0].as<double>();
                                const std::int64_t count = *a[1].as<std::int32_t>();
                                const std::size_t size = static_cast<std::size_t>(std::max(2, *a[2].as<std::int32_t>()));
                                std::lock_guard lock(senders_mutex);
                                senders.emplace_back([=, &stopping] { send_ticks(*ticks_raw, hz, count, size, stopping); });
                                return Value();
                            }),
         "StartTicks");
    auto packets = must(root->pipe("Packets"), "Packets");
    std::atomic<std::uint64_t> packets_received{0};
    packets->on_packet([&](const std::shared_ptr<PipeEndpoint>&, Value) { packets_received.fetch_add(1); });
    auto buffer = must(root->memory("Buffer"), "Buffer");
    const auto doubles = static_cast<std::size_t>(memory_mib * 1024 * 1024 / sizeof(double));
    must(buffer->set_contents(Value(NumericArray::zeros(DataTypes::double_t, doubles))), "Buffer contents");

    auto service = must(ObjectService::create("bench", root), "service");
    NodeOptions options;
    options.node_name = local ? std::string() : "bench_service";  // rr+local by NodeID: no NodeName to hold
    options.threads = threads;
    auto node = Node::create(options);
    must(node->register_service(service), "register");
    std::shared_ptr<http::HttpServer> http_server;  // kept for the whole run: the listener holds it weakly
    TcpListenerOptions tcp;
    if (websocket) {
        http_server = std::make_shared<http::HttpServer>(node, http::HttpOptions{});
        tcp.http = http::http_handler(http_server);
    }
    const std::uint16_t bound = must(listen_tcp(node, "127.0.0.1", port, std::move(tcp)), "listen");
    if (local) must(local::listen_local(node), "rr+local");

    if (tick_hz > 0) {
        std::lock_guard lock(senders_mutex);
        senders.emplace_back([&] { send_ticks(*ticks_raw, tick_hz, -1, static_cast<std::size_t>(tick_size), stopping); });
    }
    if (frame_hz > 0) {
        std::lock_guard lock(senders_mutex);
        senders.emplace_back([&, w = frames.get()] { send_frames(*w, frame_hz, frame_bytes, stopping); });
    }

    nlohmann::json ready = {{"url", "rr+tcp://127.0.0.1:" + std::to_string(bound) + "/?service=bench"},
                            {"port", bound},
                            {"pid", static_cast<int>(getpid())}};
    if (websocket) ready["ws_url"] = "rr+ws://127.0.0.1:" + std::to_string(bound) + "/?service=bench";
    if (local) ready["local_url"] = "rr+local:///?nodeid=" + node->node_id().to_string() + "&service=bench";
    std::cout << ready.dump() << std::endl;

    while (!g_stop) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    stopping = true;
    {
        std::lock_guard lock(senders_mutex);
        for (auto& t : senders) t.join();
    }
    node->shutdown();
    service->shutdown();
    root->clear_handlers();
    return 0;
}
