#include "test/fuzz/gateway_harness.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <thread>

#include "server/app/gateway.hpp"
#include "server/app/log.hpp"
#include "server/app/demo_starter.hpp"
#include "server/gateway/json_api_installer.hpp"

namespace rr::fuzz {

void fail_input(const std::string& what) {
    std::fprintf(stderr, "fuzz finding: %s\n", what.c_str());
    std::fflush(stderr);
    std::abort();
}

namespace {

std::string make_web_root() {
    namespace fs = std::filesystem;
    std::string tmpl = (fs::temp_directory_path() / "rr-fuzz-XXXXXX").string();
    if (!::mkdtemp(tmpl.data())) fail_input("cannot make a temporary folder");
    const fs::path base = tmpl;
    static std::string removed_at_exit;  // the folder, so a fuzz run leaves nothing in /tmp
    removed_at_exit = tmpl;
    std::atexit([] {
        std::error_code ignored;
        std::filesystem::remove_all(removed_at_exit, ignored);
    });
    fs::create_directories(base / "www" / "sub");
    std::ofstream(base / "www" / "index.html") << "<!doctype html><title>rr-fuzz</title>\n";
    std::ofstream(base / "www" / "sub" / "a.txt") << "a\n";
    std::ofstream(base / "secret.txt") << kCanary << "\n";
    std::ofstream(base / "www.txt") << kCanary << "\n";  // a sibling whose name starts like the root
    return (base / "www").string();
}

GatewayHarness* start() {
    using namespace std::chrono_literals;
    server::app::set_log_level(server::app::LogLevel::error);
    auto* h = new GatewayHarness();  // never freed: the gateway lives as long as the process
    h->web_root = make_web_root();
    server::app::GatewayConfig config;
    config.listen = "127.0.0.1";
    config.port = 0;
    config.node_name = "rr.fuzz.gateway";
    config.threads = 2;
    config.web_root = h->web_root;
    config.demo = true;
    config.demo_port = 0;
    config.local = false;  // no rr+local node directory entries from a fuzzing process
    // No UDP discovery either (on by default): what the network announces must not change what an input does.
    config.discovery.enabled = false;
    // The demo devices of demo_starter(), with 16x12 webcam images: a 320x240 frame as JSON takes
    // tens of milliseconds under the sanitizers, which would make every frame-touching input slow.
    server::demo::DemoOptions demo;
    demo.webcam.width = 16;
    demo.webcam.height = 12;
    server::app::DemoStarter starter = [demo](const std::shared_ptr<server::Node>& node, std::uint16_t port,
                                              const server::app::DemoLogin& login)
        -> Result<std::vector<server::gateway::DeviceConfig>> {
        const auto options = server::app::demo_options_with_login(demo, login);
        auto devices = server::demo::start_demo_devices(*node, options);
        if (!devices) return devices.take_error();
        return server::app::demo_device_configs(port, options, login);
    };
    auto g = server::app::Gateway::start(
        config, starter,
        [h](server::http::HttpServer& http, const std::vector<std::shared_ptr<server::gateway::DeviceMirror>>& d,
            std::shared_ptr<server::gateway::auth::GatewayAuth> auth) {
            auto api = server::gateway::install_json_api(http, d, std::move(auth));
            h->http = &http;
            return api;
        });
    if (!g) fail_input("the gateway does not start: " + g.error().message);
    h->port = (*g)->port();
    const auto until = std::chrono::steady_clock::now() + 60s;
    while (!(*g)->ready()) {
        if (std::chrono::steady_clock::now() > until) fail_input("the demo devices did not connect within 60 s");
        std::this_thread::sleep_for(20ms);
    }
    if (!h->http) fail_input("the JSON API was not installed");
    h->keep = std::shared_ptr<server::app::Gateway>(std::move(*g));
    return h;
}

}  // namespace

const GatewayHarness& gateway() {
    static GatewayHarness* h = start();
    return *h;
}

}  // namespace rr::fuzz
