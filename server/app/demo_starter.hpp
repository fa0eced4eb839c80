// The gateway's demo devices (server/demo) as gateway devices: what rr-gateway's DemoStarter does. Here
// in app/, which composes the layers, so that server/demo does not depend on server/gateway.
#pragma once

#include <cstdint>
#include <vector>

#include "server/app/gateway.hpp"
#include "server/demo/demo_devices.hpp"
#include "server/gateway/device_mirror.hpp"

namespace rr::server::app {

/// The demo services on a node listening on 127.0.0.1:`port`, as devices named after the services:
/// {create, rr+tcp://127.0.0.1:PORT/?service=create}, {webcam, …?service=webcam}, logging in with
/// `login` when it is required.
std::vector<gateway::DeviceConfig> demo_device_configs(std::uint16_t port, const demo::DemoOptions& options = {},
                                                       const DemoLogin& login = {});

/// `options` with its users set to `login`'s one user when a login is required (no privileges: the
/// gateway's shared session takes no object locks).
demo::DemoOptions demo_options_with_login(demo::DemoOptions options, const DemoLogin& login);

/// demo::start_demo_devices on `node` (listening on 127.0.0.1:`port`), its services requiring `login`
/// when that is required, then demo_device_configs. Errors: those of start_demo_devices (a service
/// name already taken on the node).
Result<std::vector<gateway::DeviceConfig>> start_demo_devices_for_gateway(Node& node, std::uint16_t port,
                                                                          const DemoLogin& login = {});

}  // namespace rr::server::app
