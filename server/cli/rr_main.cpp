// rr: command-line client for Robot Raconteur services (docs/cli.md).
//   rr info URL | get URL MEMBER | set URL MEMBER JSON | call URL FUNCTION [JSON...] | watch URL MEMBER
#include <atomic>
#include <csignal>
#include <signal.h>
#include <iostream>
#include <string>
#include <vector>

#include "server/cli/cli_commands.hpp"
#include "server/cli/cli_options.hpp"
#include "server/cli/cli_usb.hpp"

namespace {

std::atomic<bool> g_stop{false};

extern "C" void on_signal(int) { g_stop.store(true); }

}  // namespace

int main(int argc, char** argv) {
    using namespace rr::cli;
    std::vector<std::string> args(argv + 1, argv + argc);
    auto cl = parse_command_line(args);
    if (!cl) {
        std::cerr << "rr: " << cl.error().message << "\n";
        return static_cast<int>(ExitCode::usage_error);
    }
    if (cl->kind == CommandKind::help) {
        auto text = help_text(cl->help_topic);
        if (text.empty()) {
            std::cerr << "rr: no help for \"" << cl->help_topic << "\"\n" << help_text("");
            return static_cast<int>(ExitCode::usage_error);
        }
        std::cout << text;
        return static_cast<int>(ExitCode::ok);
    }
    // SIGINT / SIGTERM end a watch cleanly (endpoints closed, DisconnectClient sent).
    struct sigaction sa {};
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, nullptr);
    sigaction(SIGTERM, &sa, nullptr);
    std::signal(SIGPIPE, SIG_IGN);
    // rr+usb in the client's transports; libusb starts only when an rr+usb URL or discover needs it.
    auto usb = install_usb_transport();
    const auto code = run_command(*cl, std::cout, std::cerr, g_stop);
    usb.reset();
    return static_cast<int>(code);
}
