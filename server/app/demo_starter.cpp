#include "server/app/demo_starter.hpp"

namespace rr::server::app {

std::vector<gateway::DeviceConfig> demo_device_configs(std::uint16_t port, const demo::DemoOptions& options,
                                                       const DemoLogin& login) {
    std::vector<gateway::DeviceConfig> out;
    for (auto& d : demo::demo_device_urls(port, options)) {
        gateway::DeviceConfig c;
        c.name = std::move(d.service);
        c.url = std::move(d.url);
        if (login.required()) {
            c.username = login.username;
            c.password = login.password;
        }
        out.push_back(std::move(c));
    }
    return out;
}

demo::DemoOptions demo_options_with_login(demo::DemoOptions options, const DemoLogin& login) {
    if (login.required()) {
        PasswordTable users;
        users.add_user(login.username, login.password);
        options.users = std::move(users);
    }
    return options;
}

Result<std::vector<gateway::DeviceConfig>> start_demo_devices_for_gateway(Node& node, std::uint16_t port,
                                                                          const DemoLogin& login) {
    const auto options = demo_options_with_login({}, login);
    auto devices = demo::start_demo_devices(node, options);
    if (!devices) return devices.take_error();
    return demo_device_configs(port, options, login);
}

}  // namespace rr::server::app
