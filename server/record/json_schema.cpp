#include "server/record/json_schema.hpp"

#include <optional>
#include <string>
#include <vector>

namespace rr::server::record {
namespace {

using nlohmann::json;

// The schemas are written in the subset of JSON Schema that Foxglove's and Lichtblick's channel parser
// reads (packages/mcap-support/src/parseJsonSchema.ts, see docs/recording.md "Opening a recording in
// Foxglove or Lichtblick"): every property has one `type` (boolean, string, number, integer, object or
// array), an object has `properties`, an array's `items` has one type that is not an array, and there is
// no `$ref`. Anything else makes that parser refuse the whole channel. A value that the subset cannot
// describe is left out of its object's `properties` (the message still carries it; validators accept
// properties not listed) and named in the object's description.

// What the JSON mapping (docs/json-mapping.md) writes for a scalar. Doubles and 64-bit integers may also
// be strings ("NaN", "Infinity", "-Infinity"; integers beyond 2^53): the subset has one type per field,
// the number, which is what Foxglove plots; the strings are described, not declared.
json scalar_schema(DataTypes base) {
    switch (base) {
        case DataTypes::double_t:
        case DataTypes::single_t:
            return json{{"type", "number"},
                        {"description", "non-finite values are the strings NaN, Infinity, -Infinity"}};
        case DataTypes::int64_t:
        case DataTypes::uint64_t:
            return json{{"type", "integer"}, {"description", "beyond 2^53 a decimal string"}};
        case DataTypes::int8_t:
        case DataTypes::uint8_t:
        case DataTypes::int16_t:
        case DataTypes::uint16_t:
        case DataTypes::int32_t:
        case DataTypes::uint32_t: return json{{"type", "integer"}};
        case DataTypes::cdouble_t:
        case DataTypes::csingle_t: {
            json part{{"type", "number"}};
            return json{{"type", "object"}, {"properties", {{"re", part}, {"im", part}}}, {"required", {"re", "im"}}};
        }
        case DataTypes::bool_t: return json{{"type", "boolean"}};
        case DataTypes::string_t: return json{{"type", "string"}};
        case DataTypes::varvalue_t:
            // {"type": RR type name, "value": anything}: the value has no single type, so it is not listed.
            return json{{"type", "object"},
                        {"properties", {{"type", {{"type", "string"}}}}},
                        {"description", "varvalue: {\"type\": RR type, \"value\": any}, or null"}};
        default: return json();  // not expressible
    }
}

class SchemaBuilder {
public:
    SchemaBuilder(const robdef::TypeLookup& lookup) : lookup_(lookup) {}

    // The schema of a value of `type`, or nothing when the subset cannot describe it.
    std::optional<json> value(const robdef::TypeDefinition& type, std::string_view context) {
        if (type.is_void()) return std::nullopt;
        auto item = item_schema(type, context);
        if (!item) return std::nullopt;
        json s = std::move(*item);
        if (type.array == robdef::ArrayKind::array) {
            if (s["type"] == "array") return std::nullopt;  // never: items are scalars or objects
            json a{{"type", "array"}, {"items", std::move(s)}};
            if (type.array_length.size() == 1 && type.array_length[0] > 0) {
                a["maxItems"] = type.array_length[0];
                if (!type.array_var_length) a["minItems"] = type.array_length[0];
            }
            s = std::move(a);
        } else if (type.array == robdef::ArrayKind::multidimarray) {
            s = json{{"type", "object"},
                     {"properties", {{"dims", {{"type", "array"}, {"items", {{"type", "integer"}}}}},
                                     {"array", {{"type", "array"}, {"items", std::move(s)}}}}},
                     {"required", {"dims", "array"}}};
        }
        switch (type.container) {
            case robdef::ContainerKind::list:
                if (s["type"] == "array") return std::nullopt;  // a list of arrays: items may not be arrays
                return json{{"type", "array"}, {"items", std::move(s)}, {"description", "a list, or null"}};
            case robdef::ContainerKind::map_int32:
            case robdef::ContainerKind::map_string:
                // Keys are data, not fields: Foxglove sees an object without fields; validators check the values.
                return json{{"type", "object"},
                            {"properties", json::object()},
                            {"additionalProperties", std::move(s)},
                            {"description", "a map, or null"}};
            default: return s;
        }
    }

    // Properties and required names of `fields` (name, type); unexpressible ones go to `left_out`.
    json object_of(const std::vector<std::pair<std::string, const robdef::TypeDefinition*>>& fields,
                   std::string_view context) {
        json props = json::object();
        json required = json::array();
        std::vector<std::string> left_out;
        for (const auto& [name, type] : fields) {
            auto s = value(*type, context);
            if (!s) {
                left_out.push_back(name);
                continue;
            }
            props[name] = std::move(*s);
            // A value that may be null is left out of its object's JSON when null (recording.cpp).
            if (!may_be_null(*type, context)) required.push_back(name);
        }
        json o{{"type", "object"}, {"properties", std::move(props)}, {"required", std::move(required)}};
        if (!left_out.empty()) o["description"] = "not described (no single JSON Schema type): " + json(left_out).dump();
        return o;
    }

private:
    // Whether the JSON mapping can give null for a value of `type`: a list, a map, a varvalue or a struct.
    bool may_be_null(const robdef::TypeDefinition& type, std::string_view context) const {
        if (type.container != robdef::ContainerKind::none) return true;
        if (type.base == DataTypes::varvalue_t) return true;
        if (type.base != DataTypes::namedtype_t || type.array != robdef::ArrayKind::none) return false;
        auto ref = lookup_.find(type.type_name, context);
        return ref && ref.entry && ref.entry->kind == robdef::EntryKind::structure;
    }

    std::optional<json> item_schema(const robdef::TypeDefinition& type, std::string_view context) {
        if (type.base != DataTypes::namedtype_t) {
            json s = scalar_schema(type.base);
            if (s.is_null()) return std::nullopt;
            return s;
        }
        auto ref = lookup_.find(type.type_name, context);
        if (!ref) return std::nullopt;  // unknown type
        const std::string qualified = ref.service->name + "." + (ref.entry ? ref.entry->name : ref.enumeration->name);
        if (ref.enumeration) {
            json names = json::array();
            for (const auto& v : ref.enumeration->values) names.push_back(v.name);
            return json{{"type", "integer"}, {"title", qualified}, {"description", "enum " + qualified + ": " + names.dump()}};
        }
        if (ref.entry->kind == robdef::EntryKind::object) return std::nullopt;
        // Inlined (the parser follows no $ref); a struct inside itself is an object without fields.
        for (const auto& open : open_) {
            if (open == qualified)
                return json{{"type", "object"},
                            {"properties", json::object()},
                            {"title", qualified},
                            {"description", "recursive " + qualified + ", not expanded"}};
        }
        open_.push_back(qualified);
        std::vector<std::pair<std::string, const robdef::TypeDefinition*>> fields;
        for (const auto& m : ref.entry->members)
            if (m.kind == robdef::MemberKind::field) fields.emplace_back(m.name, &m.type);
        json s = object_of(fields, ref.service->name);
        open_.pop_back();
        s["title"] = qualified;
        if (ref.entry->kind == robdef::EntryKind::structure) {
            std::string d = "struct " + qualified + ", or null";
            if (s.contains("description")) d += "; " + s["description"].get<std::string>();
            s["description"] = d;
        }
        return s;
    }

    const robdef::TypeLookup& lookup_;
    std::vector<std::string> open_;  // named types being expanded
};

json message_schema(json object, std::string_view title) {
    json s{{"$schema", "https://json-schema.org/draft/2020-12/schema"}, {"title", std::string(title)}};
    s.update(object);
    return s;
}

}  // namespace

nlohmann::json value_schema(const robdef::TypeDefinition& type, const robdef::TypeLookup& lookup,
                            std::string_view context_service) {
    SchemaBuilder b(lookup);
    auto s = b.value(type, context_service);
    return s ? std::move(*s) : json();
}

nlohmann::json wire_message_schema(const robdef::TypeDefinition& type, const robdef::TypeLookup& lookup,
                                   std::string_view context_service, std::string_view title) {
    SchemaBuilder b(lookup);
    json o = b.object_of({{"value", &type}}, context_service);
    json time{{"type", "object"},
              {"properties", {{"seconds", {{"type", "integer"}}}, {"nanoseconds", {{"type", "integer"}}}}},
              {"required", {"seconds", "nanoseconds"}}};
    o["properties"]["time"] = std::move(time);
    o["required"].push_back("time");
    return message_schema(std::move(o), title);
}

nlohmann::json value_message_schema(const robdef::TypeDefinition& type, const robdef::TypeLookup& lookup,
                                    std::string_view context_service, std::string_view title) {
    SchemaBuilder b(lookup);
    return message_schema(b.object_of({{"value", &type}}, context_service), title);
}

nlohmann::json event_message_schema(const robdef::MemberDefinition& event, const robdef::TypeLookup& lookup,
                                    std::string_view context_service, std::string_view title) {
    SchemaBuilder b(lookup);
    std::vector<std::pair<std::string, const robdef::TypeDefinition*>> params;
    for (const auto& p : event.parameters) params.emplace_back(p.name, &p);
    json o{{"type", "object"},
           {"properties", {{"args", b.object_of(params, context_service)}}},
           {"required", {"args"}}};
    return message_schema(std::move(o), title);
}

}  // namespace rr::server::record
