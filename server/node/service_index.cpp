#include "server/node/service_index.hpp"

#include <algorithm>

#include "core/value/pack_value.hpp"
#include "robdef/builtin/service_index.hpp"
#include "server/node/node.hpp"
#include "server/service/object_service.hpp"

namespace rr::server {

namespace {

std::string qualified(std::string_view name) {
    return std::string(robdef::kServiceIndexServiceName) + "." + std::string(name);
}

// CORE keeps only array-valued attributes (strings and numeric arrays) in ServiceInfo.
MapString index_attributes(const Service& service) {
    MapString out;
    auto all = unpack_value_untyped(service.attributes());
    const MapString* map = all ? all->get_if<MapString>() : nullptr;
    if (!map) return out;
    for (const auto& [key, value] : map->entries) {
        if (value.kind() == ValueKind::string || value.kind() == ValueKind::numeric)
            out.entries.emplace_back(key, value);
    }
    return out;
}

Value service_info(const Service& service, const std::string& name, const std::string& url) {
    const auto root = service.root_type();
    MapInt32 implements;
    for (std::size_t i = 0; i < root.implements.size(); ++i)
        implements.entries.emplace_back(static_cast<std::int32_t>(i), Value(root.implements[i]));
    MapInt32 urls;
    urls.entries.emplace_back(1, Value(url));
    Structure s{qualified("ServiceInfo"), {}};
    s.set("Name", Value(name));
    s.set("RootObjectType", Value(root.object_type));
    s.set("RootObjectImplements", Value(std::move(implements)));
    s.set("ConnectionURL", Value(std::move(urls)));
    s.set("Attributes", Value(index_attributes(service)));
    return Value(std::move(s));
}

}  // namespace

Result<std::shared_ptr<Service>> make_service_index(std::weak_ptr<Node> weak_node) {
    auto types = ServiceTypes::create({std::string(robdef::service_index_robdef())});
    if (!types) return types.take_error();
    auto root = ServiceObject::create(*types, robdef::kServiceIndexObjectType);
    if (!root) return root.take_error();
    auto self_name = std::string(robdef::kServiceIndexServiceName);
    auto r = (*root)->set_function("GetLocalNodeServices", [weak_node, self_name](const SessionRef& session,
                                                                                 std::vector<Value>) -> Result<Value> {
        auto node = weak_node.lock();
        if (!node) return fail(MessageErrorType::ServiceNotFound, "node is shutting down");
        std::string base = session.local_url();
        if (base.empty()) base = node->listen_base_url();
        auto names = node->service_names();
        if (std::find(names.begin(), names.end(), self_name) == names.end()) names.push_back(self_name);
        std::sort(names.begin(), names.end());
        MapInt32 out;
        std::int32_t key = 0;
        for (const auto& name : names) {
            auto service = node->find_service(name);
            if (!service) continue;  // unregistered meanwhile
            std::string url = base + "?nodeid=" + node->node_id().to_string() + "&service=" + name;
            out.entries.emplace_back(key++, service_info(*service, name, url));
        }
        return Value(std::move(out));
    });
    if (!r) return r.take_error();
    for (const char* f : {"GetRoutedNodes", "GetDetectedNodes"}) {
        r = (*root)->set_function(f, [](const SessionRef&, std::vector<Value>) -> Result<Value> { return Value(MapInt32{}); });
        if (!r) return r.take_error();
    }
    auto service = ObjectService::create(self_name, *root);
    if (!service) return service.take_error();
    return std::shared_ptr<Service>(*service);
}

void local_node_services_changed(const std::shared_ptr<Service>& index) {
    // Clients that cannot take it (full queue) miss it, as any event.
    if (auto s = std::dynamic_pointer_cast<ObjectService>(index)) (void)s->root()->fire_event("LocalNodeServicesChanged", {});
}

}  // namespace rr::server
