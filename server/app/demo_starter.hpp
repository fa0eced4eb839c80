// The gateway's demo devices (server/demo) as gateway devices: what rr-gateway's DemoStarter does. Here
// in app/, which composes the layers, so that server/demo does not depend on server/gateway.
#pragma once

#include <cstdint>
#include <vector>

#include "server/demo/demo_devices.hpp"
#include "server/gateway/device_mirror.hpp"

namespace rr::server::app {

/// The demo services on a node listening on 127.0.0.1:`port`, as devices named after the services:
/// {create, rr+tcp://127.0.0.1:PORT/?service=create}, {webcam, …?service=webcam}.
std::vector<gateway::DeviceConfig> demo_device_configs(std::uint16_t port, const demo::DemoOptions& options = {});

/// demo::start_demo_devices on `node` (listening on 127.0.0.1:`port`), then demo_device_configs.
/// Errors: those of start_demo_devices (a service name already taken on the node).
Result<std::vector<gateway::DeviceConfig>> start_demo_devices_for_gateway(Node& node, std::uint16_t port);

}  // namespace rr::server::app
