// demo_starter() of server/app/gateway_extensions.hpp: the gateway's built-in demo devices.
#include "server/app/gateway_extensions.hpp"
#include "server/demo/demo_devices.hpp"

namespace rr::server::app {

DemoStarter demo_starter() {
    return [](const std::shared_ptr<Node>& demo_node, std::uint16_t port) -> Result<std::vector<gateway::DeviceConfig>> {
        if (!demo_node) return fail(MessageErrorType::InvalidArgument, "demo devices: no node");
        auto devices = demo::start_demo_devices(*demo_node);
        if (!devices) return devices.take_error();
        return demo::demo_device_configs(port);
    };
}

}  // namespace rr::server::app
