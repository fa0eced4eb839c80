#include "core/discovery/service_info.hpp"

#include <algorithm>

namespace rr::discovery {

namespace {

Unexpected mismatch(const std::string& what) {
    return fail(MessageErrorType::DataTypeMismatch, "service index: " + what);
}

Result<std::string> string_field(const Structure& s, std::string_view name, const ServiceInfoLimits& limits) {
    const Value* v = s.find(name);
    if (!v || v->is_null()) return std::string();
    const auto* str = v->get_if<std::string>();
    if (!str) return mismatch(std::string(name) + " is not a string");
    if (str->size() > limits.max_string) return fail(MessageErrorType::OutOfRange, "service index: " + std::string(name) + " too long");
    return *str;
}

// string{int32} in key order.
Result<std::vector<std::string>> string_map_field(const Structure& s, std::string_view name,
                                                  const ServiceInfoLimits& limits) {
    std::vector<std::string> out;
    const Value* v = s.find(name);
    if (!v || v->is_null()) return out;
    const auto* map = v->get_if<MapInt32>();
    if (!map) return mismatch(std::string(name) + " is not a string{int32}");
    if (map->entries.size() > limits.max_list)
        return fail(MessageErrorType::OutOfRange, "service index: too many " + std::string(name));
    std::vector<std::pair<std::int32_t, const std::string*>> items;
    for (const auto& [key, item] : map->entries) {
        const auto* str = item.get_if<std::string>();
        if (!str) return mismatch(std::string(name) + " holds a non-string");
        if (str->size() > limits.max_string)
            return fail(MessageErrorType::OutOfRange, "service index: " + std::string(name) + " entry too long");
        items.emplace_back(key, str);
    }
    std::stable_sort(items.begin(), items.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    for (const auto& [key, str] : items) out.push_back(*str);
    return out;
}

}  // namespace

std::string url_scheme(std::string_view url) {
    auto p = url.find("://");
    return p == std::string_view::npos ? std::string() : std::string(url.substr(0, p));
}

Result<std::vector<ServiceInfo2>> service_infos_from_value(const Value& value, const NodeID& node_id,
                                                           const std::string& node_name,
                                                           const ServiceInfoLimits& limits) {
    std::vector<ServiceInfo2> out;
    if (value.is_null()) return out;
    const auto* map = value.get_if<MapInt32>();
    if (!map) return mismatch("GetLocalNodeServices did not return ServiceInfo{int32}");
    if (map->entries.size() > limits.max_services) return fail(MessageErrorType::OutOfRange, "service index: too many services");
    std::vector<std::pair<std::int32_t, const Value*>> entries;
    for (const auto& [key, v] : map->entries) entries.emplace_back(key, &v);
    std::stable_sort(entries.begin(), entries.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    for (const auto& [key, v] : entries) {
        if (v->is_null()) continue;  // CORE skips null entries
        const auto* s = v->get_if<Structure>();
        if (!s) return mismatch("a ServiceInfo is not a struct");
        ServiceInfo2 info;
        info.node_id = node_id;
        info.node_name = node_name;
        auto name = string_field(*s, "Name", limits);
        if (!name) return name.take_error();
        info.name = std::move(*name);
        auto root = string_field(*s, "RootObjectType", limits);
        if (!root) return root.take_error();
        info.root_object_type = std::move(*root);
        auto impl = string_map_field(*s, "RootObjectImplements", limits);
        if (!impl) return impl.take_error();
        info.root_object_implements = std::move(*impl);
        auto urls = string_map_field(*s, "ConnectionURL", limits);
        if (!urls) return urls.take_error();
        info.connection_urls = std::move(*urls);
        if (const Value* a = s->find("Attributes"); a && !a->is_null()) {
            const auto* attrs = a->get_if<MapString>();
            if (!attrs) return mismatch("Attributes is not a varvalue{string}");
            if (attrs->entries.size() > limits.max_attributes)
                return fail(MessageErrorType::OutOfRange, "service index: too many attributes");
            info.attributes = *attrs;
        }
        out.push_back(std::move(info));
    }
    return out;
}

}  // namespace rr::discovery
