// rr-gateway: Robot Raconteur devices re-exposed over WebSocket and HTTP.
// Usage: rr-gateway [--config FILE] [options]   (see --help and docs/gateway-config.md)
#include <atomic>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <string>
#include <thread>

#include "server/app/gateway.hpp"
#include "server/app/gateway_auth_config.hpp"
#include "server/app/log.hpp"
#include "server/app/malloc_tuning.hpp"
#include "server/app/web_root.hpp"
#include "server/app/demo_starter.hpp"
#include "server/gateway/json_api_installer.hpp"

using namespace rr;
using namespace rr::server::app;

namespace {
std::atomic<bool> g_stop{false};  // lock-free: safe to set from a signal handler
std::atomic<bool> g_reload{false};
void on_signal(int) { g_stop.store(true); }
void on_hangup(int) { g_reload.store(true); }
// SIGHUP: the TLS certificate (renewed by certbot & co.; open connections keep theirs), and gateway.auth's
// users, tokens, JWT key and roles read again from the configuration file. A file that does not load
// leaves what is in force; everything else in the file needs a restart (docs/security.md).
void reload_on_hangup(Gateway& gateway, const CommandLine& cmd) {
    if (!gateway.tls()) {
        log(LogLevel::info, "SIGHUP: no TLS configured, no certificate to reload");
    } else if (auto r = gateway.reload_tls(); r) {
        log(LogLevel::info, "SIGHUP: TLS certificate reloaded: " + gateway.tls()->describe());
    } else {
        log(LogLevel::error, "SIGHUP: TLS certificate not reloaded, the previous one stays in use: " + r.error().message);
    }
    if (!gateway.auth()) {
        log(LogLevel::info, "SIGHUP: logins are off (gateway.auth); turning them on needs a restart");
        return;
    }
    GatewayConfig config;
    if (cmd.config_file) {
        auto loaded = load_gateway_config(*cmd.config_file);
        if (!loaded) {
            log(LogLevel::error, "SIGHUP: logins not reloaded, the previous ones stay in force: " + loaded.error().message);
            return;
        }
        config = std::move(*loaded);
    }
    if (auto r = apply_overrides(config, cmd); !r) {
        log(LogLevel::error, "SIGHUP: logins not reloaded, the previous ones stay in force: " + r.error().message);
        return;
    }
    auto settings = load_gateway_auth_settings(config.auth);
    Result<void> done = settings ? (*settings ? gateway.auth()->reload(std::move(**settings))
                                              : Result<void>(fail(MessageErrorType::InvalidConfiguration,
                                                                  "gateway.auth configures no users, tokens or JWT key; "
                                                                  "restart the gateway to turn logins off")))
                                 : Result<void>(settings.take_error());
    if (!done) {
        log(LogLevel::error, "SIGHUP: logins not reloaded, the previous ones stay in force: " + done.error().message);
        return;
    }
    log(LogLevel::info, "SIGHUP: logins reloaded: " + server::gateway::auth::describe(gateway.auth()->summary()));
}

}  // namespace

int main(int argc, char** argv) {
    // Before any thread starts: keep camera-frame-sized buffers mapped (a recording otherwise costs the
    // live path ~225 page faults per frame; docs/benchmarks.md, "Recording while serving").
    const std::string malloc_tuning = tune_malloc_for_frames();
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
        if (config.tls.enabled()) {
            auto tls = load_tls(config.tls);  // the certificate files, as the start would read them
            if (!tls) {
                std::cerr << "rr-gateway: configuration error: " << tls.error().message << "\n";
                return 2;
            }
        }
        auto auth = load_gateway_auth(config.auth);  // the password, token and key files, as the start reads them
        if (!auth) {
            std::cerr << "rr-gateway: configuration error: " << auth.error().message << "\n";
            return 2;
        }
        std::cout << "configuration ok: " << config.devices.size() << " device(s)" << (config.demo ? " + demo devices" : "")
                  << ", port " << config.port << (config.tls.enabled() ? " (TLS)" : "");
        if (*auth) std::cout << ", logins: " << describe((*auth)->summary());
        std::cout << "\n";
        return 0;
    }
    set_log_level(log_level_from_string(config.log_level));
    if (LogFormat f; log_format_from_string(config.log_format, f)) set_log_format(f);
    if (!malloc_tuning.empty()) log(LogLevel::debug, malloc_tuning);

    DemoStarter demo = [](const std::shared_ptr<rr::server::Node>& node, std::uint16_t port, const DemoLogin& login) {
        return rr::server::app::start_demo_devices_for_gateway(*node, port, login);
    };
    auto gateway = Gateway::start(config, demo, rr::server::gateway::install_json_api);
    if (!gateway) {
        const bool config_error = gateway.error().type == MessageErrorType::InvalidConfiguration;
        std::cerr << "rr-gateway: " << (config_error ? "configuration error: " : "") << gateway.error().message << "\n";
        return config_error ? 2 : 1;
    }
    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    std::signal(SIGHUP, on_hangup);
    const bool tls = (*gateway)->tls() != nullptr;
    const std::string port_text = std::to_string((*gateway)->port());
    log(LogLevel::info, "rr-gateway listening on port " + port_text + " (RR rr+tcp and rr+ws" +
                            std::string(tls ? ", rrs+tcp, rr+wss" : "") + std::string(config.local ? ", rr+local" : "") +
                            (tls ? ", HTTP and HTTPS; dashboard https://localhost:" : ", HTTP; dashboard http://localhost:") +
                            port_text + "/)");
    if (tls) log(LogLevel::info, "TLS certificate: " + (*gateway)->tls()->describe());
    // The ready line, for scripts: the port, and the node's identity (rr+local:///?nodename=… / ?nodeid=…).
    std::cout << "{\"port\": " << (*gateway)->port() << ", \"nodeid\": \"" << (*gateway)->node()->node_id().to_string()
              << "\", \"nodename\": \"" << (*gateway)->node()->node_name() << "\", \"tls\": " << (tls ? "true" : "false")
              << "}" << std::endl;
    while (!g_stop) {
        std::this_thread::sleep_for(std::chrono::milliseconds(20));  // a stop is noticed within 20 ms
        if (g_reload.exchange(false)) reload_on_hangup(**gateway, *cmd);
    }
    log(LogLevel::info, "shutting down");
    (*gateway)->stop();
    return 0;
}
