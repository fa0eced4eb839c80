// What the rr-gateway executable plugs into the Gateway: the demo devices, the JSON API, and where
// the dashboard's files are by default.
#pragma once

#include "server/app/gateway.hpp"

namespace rr::server::app {

/// Starts the demo devices (experimental.create, experimental.createwebcam) on the demo node.
DemoStarter demo_starter();
/// Installs the JSON API (docs/json-api.md) on the HTTP server.
ApiInstaller api_installer();
/// The dashboard folder: `web/dist` of the source tree the binary was built from, when it exists.
std::string default_web_root(const char* argv0);

}  // namespace rr::server::app
