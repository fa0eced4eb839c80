#include "core/discovery/service_filter.hpp"

#include <algorithm>

namespace rr::discovery {

namespace {

char lower(char c) { return (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c; }

bool starts_with_scheme(std::string_view url, const std::string& scheme) {
    return url.size() > scheme.size() + 3 && url.substr(0, scheme.size()) == scheme &&
           url.substr(scheme.size(), 3) == "://";
}

template <class Values>
bool combine(FilterOperation op, const std::vector<FilterAttribute>& attrs, const std::vector<FilterAttributeGroup>& groups,
             const Values& values);

bool attr_matches(const FilterAttribute& a, const std::vector<std::string_view>& values) {
    return std::any_of(values.begin(), values.end(), [&](std::string_view v) { return a.matches(v); });
}
bool attr_matches(const FilterAttribute& a, const std::vector<std::pair<std::string_view, std::string_view>>& pairs) {
    return std::any_of(pairs.begin(), pairs.end(), [&](const auto& p) { return a.matches(p.first, p.second); });
}
bool group_matches(const FilterAttributeGroup& g, const std::vector<std::string_view>& values) {
    return g.matches_strings(values);
}
bool group_matches(const FilterAttributeGroup& g, const std::vector<std::pair<std::string_view, std::string_view>>& pairs) {
    return g.matches_pairs(pairs);
}

template <class Values>
bool combine(FilterOperation op, const std::vector<FilterAttribute>& attrs, const std::vector<FilterAttributeGroup>& groups,
             const Values& values) {
    switch (op) {
        case FilterOperation::op_or: {
            if (attrs.empty() && groups.empty()) return true;
            for (const auto& g : groups)
                if (group_matches(g, values)) return true;
            for (const auto& a : attrs)
                if (attr_matches(a, values)) return true;
            return false;
        }
        case FilterOperation::op_and: {
            for (const auto& g : groups)
                if (!group_matches(g, values)) return false;
            for (const auto& a : attrs)
                if (!attr_matches(a, values)) return false;
            return true;
        }
        case FilterOperation::op_nor: return !combine(FilterOperation::op_or, attrs, groups, values);
        case FilterOperation::op_nand: return !combine(FilterOperation::op_and, attrs, groups, values);
    }
    return false;
}

}  // namespace

std::optional<FilterOperation> parse_filter_operation(std::string_view text) {
    std::string t;
    for (char c : text) t += lower(c);
    if (t == "or") return FilterOperation::op_or;
    if (t == "and") return FilterOperation::op_and;
    if (t == "nor" || t == "not") return FilterOperation::op_nor;
    if (t == "nand") return FilterOperation::op_nand;
    return std::nullopt;
}

bool FilterAttribute::matches(std::string_view v) const {
    if (!name.empty()) return false;
    return matcher ? matcher(v) : v == value;
}

bool FilterAttribute::matches(std::string_view n, std::string_view v) const {
    if (!name.empty() && name != n) return false;
    return matcher ? matcher(v) : v == value;
}

bool FilterAttributeGroup::matches_strings(const std::vector<std::string_view>& values) const {
    return combine(operation, attributes, groups, values);
}

bool FilterAttributeGroup::matches_pairs(const std::vector<std::pair<std::string_view, std::string_view>>& pairs) const {
    return combine(operation, attributes, groups, pairs);
}

bool FilterAttributeGroup::matches(const Value* value) const {
    std::vector<std::string_view> values;
    if (!value || value->is_null()) return matches_strings(values);
    if (const auto* s = value->get_if<std::string>()) {
        if (!split_string) {
            values.push_back(*s);
        } else {
            std::string_view rest = *s;
            for (;;) {
                auto p = rest.find(delimiter);
                values.push_back(rest.substr(0, p));
                if (p == std::string_view::npos) break;
                rest = rest.substr(p + 1);
            }
        }
        return matches_strings(values);
    }
    if (const auto* l = value->get_if<List>()) {
        for (const auto& item : l->items)
            if (const auto* s = item.get_if<std::string>()) values.push_back(*s);
        return matches_strings(values);
    }
    if (const auto* m = value->get_if<MapString>()) {
        std::vector<std::pair<std::string_view, std::string_view>> pairs;
        for (const auto& [k, item] : m->entries)
            if (const auto* s = item.get_if<std::string>()) pairs.emplace_back(k, *s);
        return matches_pairs(pairs);
    }
    return false;
}

std::optional<FilterMatch> match_service(const ServiceFilter& filter, const ServiceInfo2& info,
                                         const std::vector<std::string>& node_urls) {
    FilterMatch out;
    const auto& types = filter.service_types;
    if (!types.empty() && std::find(types.begin(), types.end(), info.root_object_type) == types.end()) {
        // CORE reports a type implemented from the root's own service unqualified ("Base" for
        // "svc.Base"), as the robdef wrote it; such a name is also taken as of the root's service.
        const auto dot = info.root_object_type.rfind('.');
        const std::string service = dot == std::string::npos ? std::string() : info.root_object_type.substr(0, dot + 1);
        std::string found;
        for (const auto& t : info.root_object_implements) {
            const std::string qualified = t.find('.') == std::string::npos ? service + t : t;
            for (const auto& want : types)
                if (want == t || want == qualified) found = want;
            if (!found.empty()) break;
        }
        if (found.empty()) return std::nullopt;
        out.client_service_type = found;
    } else {
        out.client_service_type = info.root_object_type;
    }

    if (!filter.nodes.empty()) {
        bool any = false;
        for (const auto& n : filter.nodes) {
            const bool id_any = n.node_id.is_any(), name_any = n.node_name.empty();
            if ((id_any || n.node_id == info.node_id) && (name_any || n.node_name == info.node_name)) {
                any = true;
                break;
            }
        }
        if (!any) return std::nullopt;
    }

    if (filter.transport_schemes.empty()) {
        out.urls = info.connection_urls;
    } else {
        for (const auto& u : info.connection_urls)
            for (const auto& s : filter.transport_schemes)
                if (starts_with_scheme(u, s)) out.urls.push_back(u);
        if (out.urls.empty()) {
            for (const auto& u : node_urls)
                for (const auto& s : filter.transport_schemes) {
                    if (!starts_with_scheme(u, s)) continue;
                    std::string url = u;
                    auto p = url.rfind(kServiceIndexName);
                    if (p != std::string::npos) url.replace(p, kServiceIndexName.size(), info.name);
                    out.urls.push_back(std::move(url));
                }
        }
    }

    if (!filter.service_names.empty() &&
        std::find(filter.service_names.begin(), filter.service_names.end(), info.name) == filter.service_names.end())
        return std::nullopt;

    if (!filter.attributes.empty()) {
        std::vector<bool> results;
        for (const auto& [name, group] : filter.attributes) results.push_back(group.matches(info.attributes.find(name)));
        const bool any_true = std::find(results.begin(), results.end(), true) != results.end();
        const bool any_false = std::find(results.begin(), results.end(), false) != results.end();
        switch (filter.attributes_operation) {
            case FilterOperation::op_or:
                if (!any_true) return std::nullopt;
                break;
            case FilterOperation::op_nor:
                if (any_true) return std::nullopt;
                break;
            case FilterOperation::op_nand:
                if (!any_false) return std::nullopt;
                break;
            case FilterOperation::op_and:
                if (any_false) return std::nullopt;
                break;
        }
    }
    if (out.urls.empty()) return std::nullopt;
    return out;
}

}  // namespace rr::discovery
