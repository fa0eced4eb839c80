#include "server/record/json_schema.hpp"

#include <string>

namespace rr::server::record {
namespace {

using nlohmann::json;

// Scalars as docs/json-mapping.md writes them: 64-bit integers beyond 2^53 become decimal strings,
// non-finite floats the strings "NaN", "Infinity", "-Infinity"; complex numbers {"re", "im"}.
json scalar_schema(DataTypes base) {
    switch (base) {
        case DataTypes::double_t:
        case DataTypes::single_t: return json{{"type", json::array({"number", "string"})}};
        case DataTypes::int64_t:
        case DataTypes::uint64_t: return json{{"type", json::array({"integer", "string"})}};
        case DataTypes::int8_t:
        case DataTypes::uint8_t:
        case DataTypes::int16_t:
        case DataTypes::uint16_t:
        case DataTypes::int32_t:
        case DataTypes::uint32_t: return json{{"type", "integer"}};
        case DataTypes::cdouble_t:
        case DataTypes::csingle_t: {
            json part{{"type", json::array({"number", "string"})}};
            return json{{"type", "object"}, {"properties", {{"re", part}, {"im", part}}}, {"required", {"re", "im"}}};
        }
        case DataTypes::bool_t: return json{{"type", "boolean"}};
        case DataTypes::string_t: return json{{"type", "string"}};
        case DataTypes::varvalue_t:
            return json{{"type", json::array({"object", "null"})},
                        {"properties", {{"type", {{"type", "string"}}}, {"value", json::object()}}}};
        default: return json::object();
    }
}

json fields_schema(const robdef::ServiceEntryDefinition& entry, const robdef::TypeLookup& lookup,
                   std::string_view context, json& defs) {
    json props = json::object();
    json required = json::array();
    for (const auto& m : entry.members) {
        if (m.kind != robdef::MemberKind::field) continue;
        props[m.name] = value_schema(m.type, lookup, context, defs);
        required.push_back(m.name);
    }
    return json{{"type", "object"}, {"properties", std::move(props)}, {"required", std::move(required)}};
}

// The schema of one item (no array, no container): a scalar or a named type (put in `defs`).
json item_schema(const robdef::TypeDefinition& type, const robdef::TypeLookup& lookup, std::string_view context,
                 json& defs) {
    if (type.base != DataTypes::namedtype_t) return scalar_schema(type.base);
    auto ref = lookup.find(type.type_name, context);
    if (!ref) return json::object();  // unknown type: anything
    const std::string qualified = ref.service->name + "." +
                                  (ref.entry ? ref.entry->name : ref.enumeration->name);
    if (!defs.contains(qualified)) {
        defs[qualified] = json::object();  // placeholder: a recursive struct refers to itself
        json s;
        if (ref.enumeration) {
            json names = json::array();
            for (const auto& v : ref.enumeration->values) names.push_back(v.name);
            s = json{{"type", "integer"}, {"description", "enum " + qualified + ": " + names.dump()}};
        } else if (ref.entry->kind == robdef::EntryKind::object) {
            s = json::object();
        } else {
            s = fields_schema(*ref.entry, lookup, ref.service->name, defs);
            if (ref.entry->kind == robdef::EntryKind::structure) s["type"] = json::array({"object", "null"});
        }
        s["title"] = qualified;
        defs[qualified] = std::move(s);
    }
    return json{{"$ref", "#/$defs/" + qualified}};
}

json multidim_schema(json item) {
    return json{{"type", "object"},
                {"properties", {{"dims", {{"type", "array"}, {"items", {{"type", "integer"}}}}},
                                {"array", {{"type", "array"}, {"items", std::move(item)}}}}},
                {"required", {"dims", "array"}}};
}

}  // namespace

nlohmann::json value_schema(const robdef::TypeDefinition& type, const robdef::TypeLookup& lookup,
                            std::string_view context_service, nlohmann::json& defs) {
    if (type.is_void()) return json{{"type", "null"}};
    json s = item_schema(type, lookup, context_service, defs);
    if (type.array == robdef::ArrayKind::array) {
        json a{{"type", "array"}, {"items", std::move(s)}};
        if (type.array_length.size() == 1 && type.array_length[0] > 0) {
            a["maxItems"] = type.array_length[0];
            if (!type.array_var_length) a["minItems"] = type.array_length[0];
        }
        s = std::move(a);
    } else if (type.array == robdef::ArrayKind::multidimarray) {
        s = multidim_schema(std::move(s));
    }
    switch (type.container) {
        case robdef::ContainerKind::list:
            return json{{"type", json::array({"array", "null"})}, {"items", std::move(s)}};
        case robdef::ContainerKind::map_int32:
        case robdef::ContainerKind::map_string:
            return json{{"type", json::array({"object", "null"})}, {"additionalProperties", std::move(s)}};
        default: return s;
    }
}

namespace {
json message_schema(json properties, json required, json defs, std::string_view title) {
    json s{{"$schema", "https://json-schema.org/draft/2020-12/schema"},
           {"title", std::string(title)},
           {"type", "object"},
           {"properties", std::move(properties)},
           {"required", std::move(required)}};
    if (!defs.empty()) s["$defs"] = std::move(defs);
    return s;
}
}  // namespace

nlohmann::json wire_message_schema(const robdef::TypeDefinition& type, const robdef::TypeLookup& lookup,
                                   std::string_view context_service, std::string_view title) {
    json defs = json::object();
    json value = value_schema(type, lookup, context_service, defs);
    json time{{"type", "object"},
              {"properties", {{"seconds", {{"type", "integer"}}}, {"nanoseconds", {{"type", "integer"}}}}},
              {"required", {"seconds", "nanoseconds"}}};
    return message_schema(json{{"time", std::move(time)}, {"value", std::move(value)}}, json{"time", "value"},
                          std::move(defs), title);
}

nlohmann::json value_message_schema(const robdef::TypeDefinition& type, const robdef::TypeLookup& lookup,
                                    std::string_view context_service, std::string_view title) {
    json defs = json::object();
    json value = value_schema(type, lookup, context_service, defs);
    return message_schema(json{{"value", std::move(value)}}, json{"value"}, std::move(defs), title);
}

nlohmann::json event_message_schema(const robdef::MemberDefinition& event, const robdef::TypeLookup& lookup,
                                    std::string_view context_service, std::string_view title) {
    json defs = json::object();
    json args = json::object();
    json required = json::array();
    for (const auto& p : event.parameters) {
        args[p.name] = value_schema(p, lookup, context_service, defs);
        required.push_back(p.name);
    }
    json a{{"type", "object"}, {"properties", std::move(args)}, {"required", std::move(required)}};
    return message_schema(json{{"args", std::move(a)}}, json{"args"}, std::move(defs), title);
}

}  // namespace rr::server::record
