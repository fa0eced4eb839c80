#include "server/app/gateway_discovery.hpp"

#include <algorithm>

#include "base/names/connection_url.hpp"
#include "server/app/log.hpp"
#include "server/gateway/mirror_service.hpp"
#include "server/node/node.hpp"
#include "server/discovery/discovery_json.hpp"

namespace rr::server::app {

namespace core = rr::discovery;

std::string discovered_device_name(const std::string& name_template, const core::ServiceInfo2& s) {
    std::string out;
    for (std::size_t i = 0; i < name_template.size();) {
        auto put = [&](std::string_view key, const std::string& value) {
            if (name_template.compare(i, key.size(), key) != 0) return false;
            out += value;
            i += key.size();
            return true;
        };
        if (put("{service}", s.name) || put("{nodename}", s.node_name) || put("{nodeid}", s.node_id.to_string())) continue;
        out += name_template[i++];
    }
    for (auto& c : out)
        if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_')) c = '_';
    if (out.empty() || !((out[0] >= 'a' && out[0] <= 'z') || (out[0] >= 'A' && out[0] <= 'Z'))) out = "d_" + out;
    return out;
}

std::shared_ptr<DiscoveredDevices> DiscoveredDevices::create(std::shared_ptr<Node> node,
                                                             std::shared_ptr<discovery::NodeDiscovery> discovery,
                                                             std::vector<DiscoverRule> rules,
                                                             std::function<bool(const std::string&)> taken) {
    std::shared_ptr<DiscoveredDevices> d(new DiscoveredDevices());
    d->node_ = node;
    d->discovery_ = std::move(discovery);
    d->rules_ = std::move(rules);
    d->taken_ = std::move(taken);
    return d;
}

void DiscoveredDevices::set_api(std::shared_ptr<gateway::JsonApi> api) {
    std::lock_guard lock(mutex_);
    api_ = std::move(api);
}

void DiscoveredDevices::set_auth(std::shared_ptr<gateway::auth::GatewayAuth> auth) {
    std::lock_guard lock(mutex_);
    auth_ = std::move(auth);
}

void DiscoveredDevices::start() {
    std::weak_ptr<DiscoveredDevices> weak = weak_from_this();
    listener_ = discovery_->add_listener([weak](const discovery::DiscoveryEvent& e) {
        if (auto self = weak.lock()) self->on_event(e);
    });
    // The nodes' services are asked for when something needs them: the rules (now), the JSON API's list
    // (at its first request, list()). A gateway nobody asks does not interrogate every node it hears,
    // as an official node does not.
    if (!rules_.empty()) want_services();
}

void DiscoveredDevices::want_services() {
    if (services_wanted_.exchange(true)) return;
    discovery_->want_services(true);
}

void DiscoveredDevices::stop() {
    std::map<std::pair<NodeID, std::string>, Entry> entries;
    {
        std::lock_guard lock(mutex_);
        if (stopped_) return;
        stopped_ = true;
        entries.swap(entries_);
    }
    discovery_->remove_listener(listener_);
    for (auto& [k, e] : entries) retire(std::move(e), "gateway stopping");
}

void DiscoveredDevices::on_event(const discovery::DiscoveryEvent& e) {
    using Kind = discovery::DiscoveryEvent::Kind;
    if (e.kind == Kind::node_lost) return drop_node(e.node.node_id, "node " + e.node.node_id.to_string() + " lost");
    // node_updated: URLs came or went (an rr+local entry closed while UDP still knows the node, a USB
    // device unplugged): devices reached through a vanished URL go, new URLs may select services.
    if (e.kind == Kind::services_updated || e.kind == Kind::node_updated) sync_node(e.node);
}

namespace {

// Devices reached over rr+local or rr+usb stay only while the node still has a URL of that transport
// (those sources take their URLs back when the node goes). Network URLs expire with the node instead.
bool endpoint_still_known(const core::NodeEntry& node, const std::string& device_url) {
    auto d = parse_connection_url(device_url);
    if (!d || (d->scheme != "rr+local" && d->scheme != "rr+usb")) return true;
    for (const auto& u : node.urls) {
        auto n = parse_connection_url(u.url);
        if (n && n->scheme == d->scheme && n->host == d->host && n->user == d->user) return true;
    }
    return false;
}

}  // namespace

void DiscoveredDevices::sync_node(const core::NodeEntry& node) {
    if (!node.services) return;
    std::vector<std::string> node_urls;
    for (const auto& u : node.urls) node_urls.push_back(u.url);
    std::vector<Entry> gone;
    {
        std::lock_guard lock(mutex_);
        if (stopped_) return;
        // Services the node no longer offers (or now offers elsewhere) go away.
        for (auto it = entries_.begin(); it != entries_.end();) {
            if (it->first.first != node.node_id) {
                ++it;
                continue;
            }
            auto s = std::find_if(node.services->begin(), node.services->end(),
                                  [&](const core::ServiceInfo2& x) { return x.name == it->first.second; });
            bool keep = s != node.services->end();
            keep = keep && endpoint_still_known(node, it->second.url);
            if (keep && it->second.rule >= 0) {
                auto m = core::match_service(rules_[static_cast<std::size_t>(it->second.rule)].filter, *s, node_urls);
                keep = m && std::any_of(m->urls.begin(), m->urls.end(), [&](const std::string& u) {
                           auto c = discovery_->connectable_urls(u);
                           return std::find(c.begin(), c.end(), it->second.url) != c.end();
                       });
            }
            if (keep) {
                ++it;
            } else {
                gone.push_back(std::move(it->second));
                it = entries_.erase(it);
            }
        }
    }
    // Retired before new devices are made, so that a service that moved keeps its device name.
    const bool freed = frees_capped_place(gone);
    for (auto& e : gone) retire(std::move(e), "the node no longer offers it there");
    {
        std::lock_guard lock(mutex_);
        if (stopped_) return;
        for (const auto& s : *node.services) {
            if (entries_.count({node.node_id, s.name})) continue;
            for (std::size_t r = 0; r < rules_.size(); ++r) {
                auto m = core::match_service(rules_[r].filter, s, node_urls);
                if (!m) continue;
                // The service index may still list an rr+local or rr+usb URL the node no longer has.
                std::erase_if(m->urls, [&](const std::string& u) { return !endpoint_still_known(node, u); });
                if (m->urls.empty()) continue;
                if (const auto max = rules_[r].filter.max_count) {
                    const auto held = std::count_if(entries_.begin(), entries_.end(),
                                                    [&](const auto& kv) { return kv.second.rule == static_cast<int>(r); });
                    if (static_cast<std::uint32_t>(held) >= max) continue;
                }
                auto d = create_device(node, s, m->urls, static_cast<int>(r), {});
                if (!d) log(LogLevel::warning, "discover: " + s.name + " of node " + node.node_id.to_string() + ": " + d.error().message);
                break;
            }
        }
    }
    if (freed) refill_capped_rules(nullptr);
}

bool DiscoveredDevices::frees_capped_place(const std::vector<Entry>& gone) const {
    return std::any_of(gone.begin(), gone.end(), [&](const Entry& e) {
        return e.rule >= 0 && rules_[static_cast<std::size_t>(e.rule)].filter.max_count;
    });
}

void DiscoveredDevices::refill_capped_rules(const NodeID* lost) {
    // A rule at its `max` passed over other matching services; a freed place goes to one of them now,
    // as the official subscription's max count does (otherwise only their next change would). Runs on
    // the discovery strand only. A sync below that frees another place asks for one more pass instead
    // of recursing, and the passes are bounded, so two views of a node that disagree cannot loop.
    if (refilling_) {
        refill_again_ = true;
        return;
    }
    refilling_ = true;
    for (int pass = 0; pass < 4; ++pass) {
        refill_again_ = false;
        for (const auto& n : discovery_->nodes())
            if (!lost || n.node_id != *lost) sync_node(n);
        if (!refill_again_) break;
    }
    refilling_ = false;
}

void DiscoveredDevices::drop_node(const NodeID& id, const std::string& why) {
    std::vector<Entry> gone;
    {
        std::lock_guard lock(mutex_);
        for (auto it = entries_.begin(); it != entries_.end();) {
            if (it->first.first == id) {
                gone.push_back(std::move(it->second));
                it = entries_.erase(it);
            } else {
                ++it;
            }
        }
    }
    const bool freed = frees_capped_place(gone);
    for (auto& e : gone) retire(std::move(e), why);
    if (freed) refill_capped_rules(&id);
}

std::string DiscoveredDevices::unique_name(std::string base) const {
    auto used = [&](const std::string& n) {
        if (taken_ && taken_(n)) return true;
        for (const auto& [k, e] : entries_)
            if (e.mirror->config().name == n) return true;
        return api_ && api_->find_device(n) != nullptr;
    };
    if (!used(base)) return base;
    for (int i = 2;; ++i)
        if (!used(base + "_" + std::to_string(i))) return base + "_" + std::to_string(i);
}

Result<std::shared_ptr<gateway::DeviceMirror>> DiscoveredDevices::create_device(const core::NodeEntry& node,
                                                                                const core::ServiceInfo2& service,
                                                                                const std::vector<std::string>& urls,
                                                                                int rule, std::string name) {
    auto gw = node_.lock();
    if (!gw) return fail(MessageErrorType::InvalidState, "gateway stopped");
    if (urls.empty()) return fail(MessageErrorType::ConnectionError, "the service has no URL to connect with");
    auto candidates = discovery_->connectable_urls(urls.front());
    gateway::DeviceConfig cfg;
    cfg.name = name.empty() ? unique_name(discovered_device_name(rule >= 0 ? rules_[static_cast<std::size_t>(rule)].name_template
                                                                           : std::string("{service}"),
                                                                 service))
                            : name;
    cfg.url = candidates.front();
    cfg.required = false;
    if (rule >= 0) {
        const auto& r = rules_[static_cast<std::size_t>(rule)];
        cfg.username = r.username;
        cfg.password = r.password;
        cfg.backoff_max = r.backoff_max;
    }
    cfg.safety = safety_.for_device(cfg.name);
    auto mirror = gateway::DeviceMirror::create(gw, cfg);
    if (!mirror) return mirror.take_error();
    if (auth_) (*mirror)->mirror_service()->set_access(gateway::auth::MirrorAccess(auth_, cfg.name));
    if (api_) {
        if (auto r = api_->add_device(*mirror); !r) return r.take_error();
    }
    (*mirror)->set_state_listener([](const gateway::DeviceStatus& s) {
        log(s.state == gateway::DeviceState::connected ? LogLevel::info : LogLevel::warning,
            "discovered device " + s.name + ": " + std::string(gateway::device_state_name(s.state)) +
                (s.reason.empty() ? "" : " (" + s.reason + ")"), LogContext{.device = s.name});
    });
    (*mirror)->start();
    log(LogLevel::info, "discover: device " + cfg.name + " for " + service.name + " (" + service.root_object_type +
                            ") of node " + (node.node_name.empty() ? node.node_id.to_string() : node.node_name) + " at " +
                            cfg.url);
    entries_[{node.node_id, service.name}] = Entry{node.node_id, service.name, rule, cfg.url, *mirror};
    return *mirror;
}

void DiscoveredDevices::retire(Entry e, const std::string& why) {
    if (!e.mirror) return;
    const auto name = e.mirror->config().name;
    log(LogLevel::info, "discover: removing device " + name + ": " + why);
    std::shared_ptr<gateway::JsonApi> api;
    {
        std::lock_guard lock(mutex_);
        api = api_;
    }
    // Downstream clients are told as when a device connection is lost, then the service goes away.
    e.mirror->mirror_service()->on_upstream_lost(make_error(MessageErrorType::ConnectionError,
                                                            "device \"" + name + "\" removed: " + why));
    e.mirror->stop();
    if (api) api->remove_device(name);
}

std::vector<std::shared_ptr<gateway::DeviceMirror>> DiscoveredDevices::devices() const {
    std::lock_guard lock(mutex_);
    std::vector<std::shared_ptr<gateway::DeviceMirror>> out;
    for (const auto& [k, e] : entries_) out.push_back(e.mirror);
    return out;
}

nlohmann::json DiscoveredDevices::list() {
    want_services();
    auto nodes = nlohmann::json::array();
    auto table = discovery_->nodes();
    std::lock_guard lock(mutex_);
    for (const auto& n : table) {
        auto j = discovery::node_json(n);
        if (j["services"].is_array())
            for (auto& s : j["services"]) {
                auto it = entries_.find({n.node_id, s["name"].get<std::string>()});
                s["device"] = it == entries_.end() ? nlohmann::json(nullptr) : nlohmann::json(it->second.mirror->config().name);
            }
        nodes.push_back(std::move(j));
    }
    return nlohmann::json{{"nodes", std::move(nodes)}};
}

Result<std::shared_ptr<gateway::DeviceMirror>> DiscoveredDevices::add(const NodeID& node_id, const std::string& service,
                                                                      std::string name) {
    auto node = discovery_->node(node_id);
    if (!node) return fail(MessageErrorType::NodeNotFound, "no discovered node " + node_id.to_string());
    if (!node->services) return fail(MessageErrorType::ServiceNotFound, "the services of node " + node_id.to_string() + " are not known yet");
    auto s = std::find_if(node->services->begin(), node->services->end(),
                          [&](const core::ServiceInfo2& x) { return x.name == service; });
    if (s == node->services->end())
        return fail(MessageErrorType::ServiceNotFound, "node " + node_id.to_string() + " has no service \"" + service + "\"");
    std::lock_guard lock(mutex_);
    if (stopped_) return fail(MessageErrorType::InvalidState, "gateway stopped");
    if (auto it = entries_.find({node_id, service}); it != entries_.end())
        return fail(MessageErrorType::InvalidArgument,
                    "service \"" + service + "\" is already the device \"" + it->second.mirror->config().name + "\"");
    if (!name.empty()) {
        if (discovered_device_name(name, *s) != name)
            return fail(MessageErrorType::InvalidArgument, "\"" + name + "\" is not a valid device name ([A-Za-z][A-Za-z0-9_]*)");
        if ((taken_ && taken_(name)) || (api_ && api_->find_device(name)))
            return fail(MessageErrorType::InvalidArgument, "device name \"" + name + "\" is taken");
    }
    std::vector<std::string> urls = s->connection_urls;
    if (urls.empty())
        for (const auto& u : node->urls) urls.push_back(u.url);
    return create_device(*node, *s, urls, -1, std::move(name));
}

}  // namespace rr::server::app
