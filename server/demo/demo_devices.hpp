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
#include "server/node/node.hpp"
#include "server/service/object_service.hpp"
#include "server/service/password_table.hpp"

namespace rr::server::demo {

struct DemoOptions {
    CreateDeviceOptions create;
    WebcamOptions webcam;
    std::string create_service = "create";
    std::string webcam_service = "webcam";
    /// Non-empty: both services require a login against these users (ObjectService::set_users), as
    /// rr-gateway's demo node does while gateway.auth is on. Empty: anyone may connect.
    PasswordTable users;
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

/// One demo service and the URL that reaches it.
struct DemoDeviceUrl {
    std::string service;
    std::string url;
};

/// How a client reaches them on a node listening on 127.0.0.1:`port`:
/// {create, rr+tcp://127.0.0.1:PORT/?service=create}, {webcam, rr+tcp://127.0.0.1:PORT/?service=webcam}.
/// (The gateway turns these into its devices: server/app/demo_starter.hpp.)
std::vector<DemoDeviceUrl> demo_device_urls(std::uint16_t port, const DemoOptions& options = {});

}  // namespace rr::server::demo
