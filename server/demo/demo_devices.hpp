// The two demo devices of the gateway (the seed paper's examples): service `create`
// (experimental.create.Create, create_device.hpp) and service `webcam`
// (experimental.createwebcam.WebcamHost, webcam_device.hpp), on one node.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "server/demo/create_device.hpp"
#include "server/demo/webcam_device.hpp"
#include "server/gateway/device_mirror.hpp"
#include "server/node/node.hpp"
#include "server/service/object_service.hpp"

namespace rr::server::demo {

struct DemoOptions {
    CreateDeviceOptions create;
    WebcamOptions webcam;
    std::string create_service = "create";
    std::string webcam_service = "webcam";
};

struct DemoDevices {
    std::shared_ptr<CreateDevice> create;
    std::shared_ptr<WebcamHostDevice> webcam;
    std::shared_ptr<ObjectService> create_service, webcam_service;
};

/// Builds both devices and their services; nothing is registered or started (tests drive them with
/// CreateDevice::advance and WebcamHostDevice::tick). Errors: setup errors, bad service names.
Result<DemoDevices> make_demo_devices(const DemoOptions& options = {});

/// make_demo_devices, registers both services on `node` and starts their timers on the node's
/// io_context. The node's registrations keep the devices alive: they live until the services are
/// unregistered or the node is destroyed (the returned handles are optional extra references).
/// Errors: those of make_demo_devices; InvalidArgument when a service name is taken (nothing stays
/// registered then).
Result<DemoDevices> start_demo_devices(Node& node, const DemoOptions& options = {});

/// How a gateway reaches them on a node listening on 127.0.0.1:`port`:
/// {create, rr+tcp://127.0.0.1:PORT/?service=create}, {webcam, rr+tcp://127.0.0.1:PORT/?service=webcam}.
std::vector<gateway::DeviceConfig> demo_device_configs(std::uint16_t port, const DemoOptions& options = {});

/// start_demo_devices on `node` (listening on 127.0.0.1:`port`), then demo_device_configs: what the
/// gateway's demo starter does. Errors: those of start_demo_devices.
Result<std::vector<gateway::DeviceConfig>> start_demo_devices_for_gateway(Node& node, std::uint16_t port);

}  // namespace rr::server::demo
