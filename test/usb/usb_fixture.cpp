// rr_usb_fixture: an emulated RR USB device (usb_emulator.hpp, under umockdev-wrapper) with the
// programs that use it in the same process, for the tests that run our real gateway and CLI code
// against it (test/usb/usb_gateway_test.py, usb_discover_test.py). umockdev answers the device's ioctls
// in the process that created the emulator, so the gateway and rr run here, not as children.
//
//   rr_usb_fixture gateway CONFIG.yaml
//       The device (NodeName usb_demo, the demo services `create` and `webcam` running, and `usbtest`,
//       example.usbtest.Bench) plugged in, then the gateway started from CONFIG.yaml (server/app
//       Gateway::start, the JSON API installed, no demo devices of its own). Prints one JSON line
//       {"port": N, "device_nodeid": "…", "device_nodename": "usb_demo"} and runs until SIGTERM/SIGINT
//       or stdin closes; exit status 0 after a clean stop. Lines on stdin: "unplug" takes the device
//       off the bus, "plug" puts it back (at a new address); each answers "unplugged" / "plugged" on stdout.
//   rr_usb_fixture rr ARGS…
//       The device plugged in, then the rr command line ARGS run as rr_main runs them (the CLI's
//       rr+usb connector installed); exits with rr's status.
//
// Exits 77 (skipped) when not under umockdev-wrapper.
#include <atomic>
#include <csignal>
#include <cstdlib>
#include <cstdio>
#include <iostream>
#include <string>
#include <thread>

#include <poll.h>
#include <unistd.h>

#include "server/app/gateway.hpp"
#include "server/app/log.hpp"
#include "server/cli/cli_commands.hpp"
#include "server/cli/cli_options.hpp"
#include "server/cli/cli_usb.hpp"
#include "server/demo/demo_devices.hpp"
#include "server/gateway/json_api_installer.hpp"
#include "test/usb/usb_world.hpp"

using namespace rr;
using namespace rr::test::usb;

namespace {

std::atomic<bool> g_stop{false};
extern "C" void on_signal(int) { g_stop.store(true); }
EmulatedDevice* g_device = nullptr;  // the plugged device (nullptr while unplugged)
EmulatedDeviceOptions g_device_options;  // how it was plugged (a re-plug uses them at a new address)

int usage() {
    std::fprintf(stderr, "usage: rr_usb_fixture gateway CONFIG.yaml | rr ARGS...\n");
    return 2;
}

// The emulated device with running demo devices (play_callback every second, as rr-demo-devices
// --play-period 1 in the other gateway tests) and the usbtest service.
Result<std::unique_ptr<UsbWorld>> device() {
    WorldOptions o;
    o.demo = false;  // UsbWorld's demo devices are not started; start running ones below
    auto w = UsbWorld::create(o);
    if (!w) return w.take_error();
    server::demo::DemoOptions demo;
    demo.create.play_period = std::chrono::seconds(1);
    auto d = server::demo::start_demo_devices(*(*w)->node, demo);
    if (!d) return d.take_error();
    (*w)->demo = std::move(*d);
    // RR_USB_FIXTURE_NO_BOS=1: a board without the RR BOS capability (product 0x0003), found only
    // through an allow-list entry (usb.allow).
    auto options = UsbWorld::device_options();
    if (const char* v = std::getenv("RR_USB_FIXTURE_NO_BOS"); v && std::string(v) == "1") {
        options.bos_capability = false;
        options.layout.product_id = 0x0003;
    }
    g_device_options = options;
    auto plugged = (*w)->plug(options);
    if (!plugged) return plugged.take_error();
    g_device = *plugged;
    return w;
}

int run_gateway(const std::string& config_path) {
    auto config = server::app::load_gateway_config(config_path);
    if (!config) {
        std::fprintf(stderr, "rr_usb_fixture: %s\n", config.error().message.c_str());
        return 2;
    }
    auto w = device();
    if (!w) {
        std::fprintf(stderr, "rr_usb_fixture: device: %s\n", w.error().message.c_str());
        return 1;
    }
    server::app::set_log_level(server::app::log_level_from_string(config->log_level));
    auto gw = server::app::Gateway::start(*config, {}, server::gateway::install_json_api);
    if (!gw) {
        std::fprintf(stderr, "rr_usb_fixture: gateway: %s\n", gw.error().message.c_str());
        return 1;
    }
    std::cout << "{\"port\": " << (*gw)->port() << ", \"device_nodeid\": \"" << device_node_id().to_string()
              << "\", \"device_nodename\": \"" << kDeviceNodeName << "\"}" << std::endl;
    std::string line;
    int next_address = 10;
    while (!g_stop.load()) {
        pollfd p{0, POLLIN, 0};
        if (::poll(&p, 1, 100) > 0) {
            char b[64];
            const auto n = ::read(0, b, sizeof b);
            if (n <= 0) break;  // stdin closed: the driver is gone
            line.append(b, static_cast<std::size_t>(n));
            for (auto nl = line.find('\n'); nl != std::string::npos; nl = line.find('\n')) {
                const std::string cmd = line.substr(0, nl);
                line.erase(0, nl + 1);
                if (cmd == "unplug" && g_device) {
                    (*w)->emulator->unplug(g_device);
                    g_device = nullptr;
                    std::cout << "unplugged" << std::endl;
                } else if (cmd == "plug" && !g_device) {
                    auto again = g_device_options;
                    again.address = static_cast<std::uint8_t>(next_address++);
                    auto d = (*w)->plug(again);
                    if (!d) {
                        std::fprintf(stderr, "rr_usb_fixture: plug: %s\n", d.error().message.c_str());
                        return 1;
                    }
                    g_device = *d;
                    std::cout << "plugged" << std::endl;
                }
            }
        }
    }
    (*gw)->stop();
    gw->reset();
    return 0;
}

int run_rr(std::vector<std::string> args) {
    auto w = device();
    if (!w) {
        std::fprintf(stderr, "rr_usb_fixture: device: %s\n", w.error().message.c_str());
        return 1;
    }
    auto usb = cli::install_usb_transport();
    auto cl = cli::parse_command_line(args);
    if (!cl) {
        std::cerr << "rr: " << cl.error().message << "\n";
        return static_cast<int>(cli::ExitCode::usage_error);
    }
    const auto code = cli::run_command(*cl, std::cout, std::cerr, g_stop);
    std::cout.flush();
    usb.reset();
    return static_cast<int>(code);
}

}  // namespace

int main(int argc, char** argv) {
    if (auto why = emulator_unavailable_reason(); !why.empty()) {
        std::printf("SKIP: %s\n", why.c_str());
        return 77;
    }
    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    std::signal(SIGPIPE, SIG_IGN);
    if (argc < 2) return usage();
    const std::string mode = argv[1];
    if (mode == "gateway" && argc == 3) return run_gateway(argv[2]);
    if (mode == "rr" && argc >= 3) return run_rr(std::vector<std::string>(argv + 2, argv + argc));
    return usage();
}
