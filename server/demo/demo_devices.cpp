#include "server/demo/demo_devices.hpp"

namespace rr::server::demo {

namespace {

/// What a node registration owns: the service and the device behind it (the service holds the
/// device's objects, the device's handlers hold it only weakly, so this is what keeps it alive).
template <class Device>
struct Registration {
    std::shared_ptr<ObjectService> service;
    std::shared_ptr<Device> device;
};

template <class Device>
std::shared_ptr<Service> owning_service(std::shared_ptr<ObjectService> service, std::shared_ptr<Device> device) {
    auto holder = std::make_shared<Registration<Device>>(Registration<Device>{std::move(service), std::move(device)});
    Service* raw = holder->service.get();
    return std::shared_ptr<Service>(std::move(holder), raw);  // aliasing: owns the holder
}

}  // namespace

Result<DemoDevices> make_demo_devices(const DemoOptions& options) {
    DemoDevices d;
    auto create = CreateDevice::create(options.create);
    if (!create) return create.take_error();
    d.create = *create;
    auto webcam = WebcamHostDevice::create(options.webcam);
    if (!webcam) return webcam.take_error();
    d.webcam = *webcam;
    auto cs = ObjectService::create(options.create_service, d.create->object());
    if (!cs) return cs.take_error();
    d.create_service = *cs;
    auto ws = ObjectService::create(options.webcam_service, d.webcam->object());
    if (!ws) return ws.take_error();
    d.webcam_service = *ws;
    if (!options.users.empty()) {
        d.create_service->set_users(options.users);
        d.webcam_service->set_users(options.users);
    }
    return d;
}

Result<DemoDevices> start_demo_devices(Node& node, const DemoOptions& options) {
    auto d = make_demo_devices(options);
    if (!d) return d.take_error();
    if (auto r = node.register_service(owning_service(d->create_service, d->create)); !r) return r.take_error();
    if (auto r = node.register_service(owning_service(d->webcam_service, d->webcam)); !r) {
        node.unregister_service(options.create_service);
        return r.take_error();
    }
    d->create->start(node.io_context());
    d->webcam->start(node.io_context());
    return d;
}

std::vector<DemoDeviceUrl> demo_device_urls(std::uint16_t port, const DemoOptions& options) {
    std::vector<DemoDeviceUrl> out;
    for (const std::string& name : {options.create_service, options.webcam_service})
        out.push_back({name, "rr+tcp://127.0.0.1:" + std::to_string(port) + "/?service=" + name});
    return out;
}

}  // namespace rr::server::demo
