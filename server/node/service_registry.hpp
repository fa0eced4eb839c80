// The services a node hosts, by name, and the endpoint ids of its client sessions: what every
// connection of the node asks (core's ServiceHost). Shared by the node and its connections, so a
// connection that outlives the node (a handler still queued at shutdown) never dangles.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "core/session/service_host.hpp"
#include "server/node/service.hpp"

namespace rr::server {

class ServiceRegistry : public ServiceHost {
public:
    /// Registers a service under its name. Errors: InvalidArgument when the name is taken or not a
    /// valid service name (`^[a-zA-Z][a-zA-Z0-9_]*$`, wire.md §13).
    Result<void> add(std::shared_ptr<Service> service);
    /// True when a service of that name was removed.
    bool remove(const std::string& name);
    /// Registered names, sorted (the fallback is not among them).
    std::vector<std::string> names() const;
    /// A registered service, else the fallback for its name (the node's service index), else nullptr.
    std::shared_ptr<Service> find(std::string_view name) const;
    /// The service answered for `name` when nothing of that name is registered.
    void set_fallback(std::string name, std::shared_ptr<Service> service);

    // ServiceHost
    std::shared_ptr<HostedService> hosted_service(std::string_view name) const override { return find(name); }
    std::uint32_t allocate_endpoint() override;
    void release_endpoint(std::uint32_t endpoint) override;

private:
    mutable std::mutex mutex_;
    std::map<std::string, std::shared_ptr<Service>, std::less<>> services_;
    std::string fallback_name_;
    std::shared_ptr<Service> fallback_;
    std::set<std::uint32_t> endpoints_;
};

}  // namespace rr::server
