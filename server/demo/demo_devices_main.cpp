// rr-demo-devices: the gateway's two demo devices (services `create` and `webcam`, the seed paper's
// examples) on their own node, for tests and for putting them behind a separately started gateway.
//
// Usage: rr-demo-devices [--port N] [--listen ADDR] [--node-name NAME] [--local] [--play-period S]
//                        [--max-lifetime S]
//   --port          TCP port (default 0 = ephemeral)
//   --listen        listen address (default 127.0.0.1)
//   --local         also serve rr+local under the NodeName (docs/local-transport.md); off by default, so
//                   that several copies with the default NodeName can run side by side
//   --play-period   seconds between play_callback calls while streaming (default 5; 0 = only on bumps)
//   --max-lifetime  exit after S seconds (default 0 = run until SIGTERM / SIGINT)
// When listening it prints one JSON line:
//   {"port": N, "create_url": "rr+tcp://127.0.0.1:N/?service=create", "webcam_url": "…?service=webcam",
//    "nodeid": "{…}", "nodename": "…"}
//   and with --local also "local_create_url": "rr+local:///?nodename=NAME&service=create", "local_webcam_url".
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <iostream>
#include <optional>
#include <string>
#include <thread>

#include "server/demo/demo_devices.hpp"
#include "server/transport/local/local_listener.hpp"
#include "server/transport/local/node_directories.hpp"
#include "server/transport/local/node_identity.hpp"
#include "server/transport/tcp_listener.hpp"

using namespace rr;
using namespace rr::server;

namespace {

std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop.store(true); }

[[noreturn]] void usage(const char* argv0, int code) {
    (code == 0 ? std::cout : std::cerr)
        << "usage: " << argv0
        << " [--port N] [--listen ADDR] [--node-name NAME] [--local] [--play-period S] [--max-lifetime S]\n";
    std::exit(code);
}

}  // namespace

int main(int argc, char** argv) {
    std::uint16_t port = 0;
    std::string listen = "127.0.0.1";
    std::string node_name = "rr.demo_devices";
    double play_period = 5.0, max_lifetime = 0;
    bool local = false;
    try {
        for (int i = 1; i < argc; ++i) {
            const std::string a = argv[i];
            auto value = [&]() -> std::string {
                if (i + 1 >= argc) usage(argv[0], 2);
                return argv[++i];
            };
            if (a == "--port") {
                const int p = std::stoi(value());
                if (p < 0 || p > 65535) usage(argv[0], 2);
                port = static_cast<std::uint16_t>(p);
            } else if (a == "--listen") listen = value();
            else if (a == "--node-name") node_name = value();
            else if (a == "--local") local = true;
            else if (a == "--play-period") play_period = std::stod(value());
            else if (a == "--max-lifetime") max_lifetime = std::stod(value());
            else if (a == "--help" || a == "-h") usage(argv[0], 0);
            else usage(argv[0], 2);
        }
    } catch (const std::exception&) {
        usage(argv[0], 2);
    }
    if (play_period < 0) usage(argv[0], 2);

    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);

    NodeOptions options;
    options.node_name = node_name;
    // rr+local: the NodeName is held for this process and gives the NodeID (the official NodeID cache).
    std::optional<local::NodeNameReservation> reservation;
    if (local) {
        auto r = local::reserve_node_name(local::default_node_directories(), node_name);
        if (!r) {
            std::cerr << "rr-demo-devices: rr+local: " << r.error().message << std::endl;
            return 1;
        }
        options.node_id = r->node_id;
        reservation = std::move(*r);
    }
    auto node = Node::create(options);
    demo::DemoOptions demo_options;
    demo_options.create.play_period = std::chrono::milliseconds(static_cast<long long>(play_period * 1000));
    auto devices = demo::start_demo_devices(*node, demo_options);
    if (!devices) {
        std::cerr << "rr-demo-devices: " << devices.error().message << std::endl;
        return 1;
    }
    auto bound = listen_tcp(node, listen, port);
    if (!bound) {
        std::cerr << "rr-demo-devices: " << bound.error().message << std::endl;
        return 1;
    }
    std::string local_urls;
    if (reservation) {
        auto l = local::listen_local(node, {}, std::move(reservation));
        if (!l) {
            std::cerr << "rr-demo-devices: rr+local: " << l.error().message << std::endl;
            return 1;
        }
        const std::string base = "rr+local:///?nodename=" + node_name + "&service=";
        local_urls = ", \"local_create_url\": \"" + base + "create\", \"local_webcam_url\": \"" + base + "webcam\"";
    }
    const auto configs = demo::demo_device_urls(*bound, demo_options);
    std::cout << "{\"port\": " << *bound << ", \"create_url\": \"" << configs[0].url << "\", \"webcam_url\": \""
              << configs[1].url << "\", \"nodeid\": \"" << node->node_id().to_braced_string() << "\", \"nodename\": \""
              << node_name << "\"" << local_urls << "}" << std::endl;

    const auto started = std::chrono::steady_clock::now();
    while (!g_stop.load()) {
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
        if (max_lifetime > 0 && std::chrono::steady_clock::now() - started > std::chrono::duration<double>(max_lifetime)) {
            std::cerr << "rr-demo-devices: max lifetime reached" << std::endl;
            break;
        }
    }
    node->shutdown();
    devices->create_service->shutdown();
    devices->webcam_service->shutdown();
    return 0;
}
