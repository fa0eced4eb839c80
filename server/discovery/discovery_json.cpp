#include "server/discovery/discovery_json.hpp"

#include "core/json/value_json.hpp"
#include "robdef/service_definition_set.hpp"

namespace rr::server::discovery {

nlohmann::json service_json(const rr::discovery::ServiceInfo2& s) {
    nlohmann::json attrs = nlohmann::json::object();
    robdef::TypeDefinition varvalue;
    varvalue.base = DataTypes::varvalue_t;
    robdef::ServiceDefinitionSet lookup;
    for (const auto& [name, value] : s.attributes.entries) {
        auto j = value_to_json(value, varvalue, lookup, "");
        attrs[name] = j ? *j : nlohmann::json(nullptr);  // a struct attribute cannot be shown untyped
    }
    return nlohmann::json{{"name", s.name},
                          {"nodename", s.node_name},
                          {"nodeid", s.node_id.to_string()},
                          {"root_object_type", s.root_object_type},
                          {"implements", s.root_object_implements},
                          {"urls", s.connection_urls},
                          {"attributes", std::move(attrs)}};
}

nlohmann::json node_json(const rr::discovery::NodeEntry& n) {
    nlohmann::json urls = nlohmann::json::array();
    for (const auto& u : n.urls) urls.push_back(u.url);
    nlohmann::json services = nullptr;
    if (n.services) {
        services = nlohmann::json::array();
        for (const auto& s : *n.services) services.push_back(service_json(s));
    }
    return nlohmann::json{{"nodeid", n.node_id.to_string()},
                          {"nodename", n.node_name},
                          {"urls", std::move(urls)},
                          {"source", std::string(rr::discovery::node_source_name(n.source))},
                          {"nonce", n.service_state_nonce},
                          {"services", std::move(services)},
                          {"error", n.last_error.empty() ? nlohmann::json(nullptr) : nlohmann::json(n.last_error)}};
}

}  // namespace rr::server::discovery
