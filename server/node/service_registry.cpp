#include "server/node/service_registry.hpp"

#include "server/common/random_ids.hpp"

namespace rr::server {

Result<void> ServiceRegistry::add(std::shared_ptr<Service> service) {
    const std::string& name = service->name();
    bool valid = !name.empty() && ((name[0] >= 'a' && name[0] <= 'z') || (name[0] >= 'A' && name[0] <= 'Z'));
    for (char c : name)
        valid = valid && ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_');
    if (!valid) return fail(MessageErrorType::InvalidArgument, "invalid service name \"" + name + "\"");
    std::lock_guard lock(mutex_);
    if (services_.count(name)) return fail(MessageErrorType::InvalidArgument, "service \"" + name + "\" already registered");
    services_.emplace(name, std::move(service));
    return {};
}

bool ServiceRegistry::remove(const std::string& name) {
    std::lock_guard lock(mutex_);
    return services_.erase(name) != 0;
}

std::vector<std::string> ServiceRegistry::names() const {
    std::lock_guard lock(mutex_);
    std::vector<std::string> out;
    for (const auto& [n, s] : services_) out.push_back(n);
    return out;
}

std::shared_ptr<Service> ServiceRegistry::find(std::string_view name) const {
    std::lock_guard lock(mutex_);
    auto it = services_.find(name);
    if (it != services_.end()) return it->second;
    return fallback_ && name == fallback_name_ ? fallback_ : nullptr;
}

void ServiceRegistry::set_fallback(std::string name, std::shared_ptr<Service> service) {
    std::lock_guard lock(mutex_);
    fallback_name_ = std::move(name);
    fallback_ = std::move(service);
}

std::uint32_t ServiceRegistry::allocate_endpoint() {
    std::lock_guard lock(mutex_);
    for (;;) {
        std::uint32_t id = random_endpoint_id();
        if (endpoints_.insert(id).second) return id;
    }
}

void ServiceRegistry::release_endpoint(std::uint32_t endpoint) {
    std::lock_guard lock(mutex_);
    endpoints_.erase(endpoint);
}

}  // namespace rr::server
