#include "server/app/demo_starter.hpp"

namespace rr::server::app {

std::vector<gateway::DeviceConfig> demo_device_configs(std::uint16_t port, const demo::DemoOptions& options) {
    std::vector<gateway::DeviceConfig> out;
    for (auto& d : demo::demo_device_urls(port, options)) {
        gateway::DeviceConfig c;
        c.name = std::move(d.service);
        c.url = std::move(d.url);
        out.push_back(std::move(c));
    }
    return out;
}

Result<std::vector<gateway::DeviceConfig>> start_demo_devices_for_gateway(Node& node, std::uint16_t port) {
    auto devices = demo::start_demo_devices(node);
    if (!devices) return devices.take_error();
    return demo_device_configs(port);
}

}  // namespace rr::server::app
