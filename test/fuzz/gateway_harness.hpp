// One real gateway in the fuzzing process, for the fuzz targets that drive the gateway's handlers:
// server/app's Gateway with its embedded demo devices (experimental.create as `create`,
// experimental.createwebcam as `webcam` with 16x12 images, reached over rr+tcp on loopback as in
// production), the JSON
// API (REST routes and the JSON WebSocket subprotocol), health routes, and a static web root holding
// index.html. It listens on 127.0.0.1 on an ephemeral port.
//
// Started on first use and never stopped (the process ends with it). Failures to start abort: a
// fuzz target without its gateway would test nothing.
//
// The web root lies in a fresh temporary folder next to a file holding kCanary: any response that
// contains the canary served a file from outside the web root.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "server/http/http_server.hpp"

namespace rr::fuzz {

inline constexpr std::string_view kCanary = "RR-FUZZ-CANARY-outside-the-web-root";

struct GatewayHarness {
    server::http::HttpServer* http = nullptr;  ///< the gateway's HTTP server (routes, subprotocols)
    std::uint16_t port = 0;                    ///< its TCP port on 127.0.0.1
    std::string web_root;                      ///< static files (index.html)
    std::shared_ptr<void> keep;                ///< the Gateway (never stopped)
};

/// The gateway, started on the first call (waits until both demo devices are connected).
const GatewayHarness& gateway();

/// Aborts with a message (a finding).
[[noreturn]] void fail_input(const std::string& what);

}  // namespace rr::fuzz
