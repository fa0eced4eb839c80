// The gateway's discovered devices (docs/gateway-config.md `discover:`, docs/discovery.md): every
// service of a discovered node that a `discover:` filter selects becomes a gateway device (a
// DeviceMirror, not required for /readyz) named by the rule's template; it reconnects while its node is
// seen and is removed when the node expires or stops offering the service (downstream clients told:
// wires and pipes closed, the JSON socket gets `device_removed`). The JSON API's "add" action makes a
// device of any discovered service for this run (removed the same way).
#pragma once

#include <atomic>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "server/app/gateway_config.hpp"
#include "server/gateway/device_mirror.hpp"
#include "server/gateway/json_api.hpp"
#include "server/discovery/node_discovery.hpp"

namespace rr::server {
class Node;
}

namespace rr::server::app {

/// The device name a rule's template gives for `service` (placeholders replaced, then sanitized to an
/// RR service name: [A-Za-z][A-Za-z0-9_]*, a leading non-letter gets "d_" in front).
std::string discovered_device_name(const std::string& name_template, const rr::discovery::ServiceInfo2& service);

class DiscoveredDevices : public std::enable_shared_from_this<DiscoveredDevices> {
public:
    /// `taken(name)` says whether a configured device already uses a name. `api` may be null.
    static std::shared_ptr<DiscoveredDevices> create(std::shared_ptr<Node> node,
                                                     std::shared_ptr<discovery::NodeDiscovery> discovery,
                                                     std::vector<DiscoverRule> rules,
                                                     std::function<bool(const std::string&)> taken);
    void set_api(std::shared_ptr<gateway::JsonApi> api);
    /// The gateway's users and permissions: discovered devices check them like configured ones.
    void set_auth(std::shared_ptr<gateway::auth::GatewayAuth> auth);
    /// Motion safety for discovered devices, by their name (SafetyConfig::for_device).
    void set_safety(SafetyConfig safety) { safety_ = std::move(safety); }
    /// Subscribes to discovery events, and asks the nodes for their services (ServiceInfo2) when there
    /// are rules; without rules the first list() asks.
    void start();
    /// Stops and removes every discovered device.
    void stop();

    std::vector<std::shared_ptr<gateway::DeviceMirror>> devices() const;
    /// GET /api/discovered: `{"nodes": [node_json… with "device" per service]}`. The first call also
    /// starts asking the nodes for their services (their "services" stay null until they answer).
    nlohmann::json list();
    /// The "add" action: a device for service `service` of node `node_id`, named `name` (default: the
    /// service name, sanitized and made unique). Errors: NodeNotFound / ServiceNotFound (404),
    /// InvalidArgument (400: the name is taken).
    Result<std::shared_ptr<gateway::DeviceMirror>> add(const NodeID& node_id, const std::string& service,
                                                       std::string name = {});

private:
    DiscoveredDevices() = default;
    struct Entry {
        NodeID node;
        std::string service;
        int rule = -1;  ///< -1: added by hand
        std::string url;
        std::shared_ptr<gateway::DeviceMirror> mirror;
    };
    void on_event(const discovery::DiscoveryEvent& e);
    void sync_node(const rr::discovery::NodeEntry& node);
    void drop_node(const NodeID& id, const std::string& why);
    /// Whether retiring `gone` frees a place of a rule with a `max` count.
    bool frees_capped_place(const std::vector<Entry>& gone) const;
    /// Matches every known node again (but `lost`) so that capped rules take services they passed over.
    void refill_capped_rules(const NodeID* lost);
    bool refilling_ = false;     ///< refill_capped_rules is running (discovery strand only)
    bool refill_again_ = false;  ///< a sync during it freed another place
    Result<std::shared_ptr<gateway::DeviceMirror>> create_device(const rr::discovery::NodeEntry& node,
                                                                 const rr::discovery::ServiceInfo2& service,
                                                                 const std::vector<std::string>& urls, int rule,
                                                                 std::string name);
    void retire(Entry entry, const std::string& why);
    std::string unique_name(std::string base) const;

    std::weak_ptr<Node> node_;
    std::shared_ptr<discovery::NodeDiscovery> discovery_;
    std::vector<DiscoverRule> rules_;
    std::function<bool(const std::string&)> taken_;
    std::shared_ptr<gateway::JsonApi> api_;
    std::shared_ptr<gateway::auth::GatewayAuth> auth_;
    SafetyConfig safety_;
    std::uint64_t listener_ = 0;
    mutable std::recursive_mutex mutex_;
    std::map<std::pair<NodeID, std::string>, Entry> entries_;
    bool stopped_ = false;
    std::atomic<bool> services_wanted_{false};
    void want_services();  ///< once: the discovery keeps the nodes' ServiceInfo2 fresh from now on
};

}  // namespace rr::server::app
