// rr-gateway: Robot Raconteur devices re-exposed over WebSocket and HTTP.
// Usage: rr-gateway [--config FILE] [options]   (see --help and docs/gateway-config.md)
#include <atomic>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <thread>

#include "server/app/gateway.hpp"
#include "server/app/log.hpp"
#include "server/app/web_root.hpp"
#include "server/demo/demo_devices.hpp"
#include "server/gateway/json_api_installer.hpp"

using namespace rr;
using namespace rr::server::app;

namespace {
std::atomic<bool> g_stop{false};  // lock-free: safe to set from a signal handler
void on_signal(int) { g_stop.store(true); }
}  // namespace

int main(int argc, char** argv) {
    auto cmd = parse_command_line(argc, argv);
    if (!cmd) {
        std::cerr << "rr-gateway: " << cmd.error().message << "\n";
        return 2;
    }
    if (cmd->help) {
        std::cout << usage_text();
        return 0;
    }
    GatewayConfig config;
    if (cmd->config_file) {
        auto loaded = load_gateway_config(*cmd->config_file);
        if (!loaded) {
            std::cerr << "rr-gateway: configuration error: " << loaded.error().message << "\n";
            return 2;
        }
        config = std::move(*loaded);
    }
    if (auto r = apply_overrides(config, *cmd); !r) {
        std::cerr << "rr-gateway: configuration error: " << r.error().message << "\n";
        return 2;
    }
    if (config.web_root.empty()) config.web_root = default_web_root(argv[0]);
    if (cmd->check_only) {
        std::cout << "configuration ok: " << config.devices.size() << " device(s)" << (config.demo ? " + demo devices" : "")
                  << ", port " << config.port << "\n";
        return 0;
    }
    set_log_level(log_level_from_string(config.log_level));
    if (LogFormat f; log_format_from_string(config.log_format, f)) set_log_format(f);

    DemoStarter demo = [](const std::shared_ptr<rr::server::Node>& node, std::uint16_t port) {
        return rr::server::demo::start_demo_devices_for_gateway(*node, port);
    };
    auto gateway = Gateway::start(config, demo, rr::server::gateway::install_json_api);
    if (!gateway) {
        std::cerr << "rr-gateway: " << gateway.error().message << "\n";
        return 1;
    }
    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    log(LogLevel::info, "rr-gateway listening on port " + std::to_string((*gateway)->port()) +
                            " (RR rr+tcp and rr+ws" + std::string(config.local ? ", rr+local" : "") +
                            ", HTTP; dashboard http://localhost:" +
                            std::to_string((*gateway)->port()) + "/)");
    // The ready line, for scripts: the port, and the node's identity (rr+local:///?nodename=… / ?nodeid=…).
    std::cout << "{\"port\": " << (*gateway)->port() << ", \"nodeid\": \"" << (*gateway)->node()->node_id().to_string()
              << "\", \"nodename\": \"" << (*gateway)->node()->node_name() << "\"}" << std::endl;
    while (!g_stop) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    log(LogLevel::info, "shutting down");
    (*gateway)->stop();
    return 0;
}
