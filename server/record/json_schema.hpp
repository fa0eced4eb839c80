// JSON Schema (draft 2020-12) of the gateway's JSON mapping (docs/json-mapping.md) for robdef types:
// what a recording's `json` channels declare as their schema, so that Foxglove / Lichtblick (and any
// JSON Schema validator) know the fields of each message without the service definition.
//
// Named types (structs, pods, namedarrays, enums) go to "$defs" under their qualified name and are
// referenced with "$ref", so recursive structs are finite. Types the lookup cannot resolve, and
// varvalue, are described loosely ({} or {"type": ["object", "null"]}).
#pragma once

#include <string_view>

#include <nlohmann/json.hpp>

#include "robdef/service_definition.hpp"
#include "robdef/type_lookup.hpp"

namespace rr::server::record {

/// Schema of one value of `type` as the JSON mapping writes it; named types resolved through `lookup`
/// (unqualified names in `context_service`) are added to `defs` (an object: qualified name → schema).
nlohmann::json value_schema(const robdef::TypeDefinition& type, const robdef::TypeLookup& lookup,
                            std::string_view context_service, nlohmann::json& defs);

/// The whole schema of a recorded wire value: {"time": {"seconds", "nanoseconds"}, "value": T} (the
/// JSON API's wire push body, docs/json-api.md), titled `title`.
nlohmann::json wire_message_schema(const robdef::TypeDefinition& type, const robdef::TypeLookup& lookup,
                                   std::string_view context_service, std::string_view title);
/// A recorded pipe packet or polled property: {"value": T}.
nlohmann::json value_message_schema(const robdef::TypeDefinition& type, const robdef::TypeLookup& lookup,
                                    std::string_view context_service, std::string_view title);
/// A recorded event: {"args": {parameter: T, …}}.
nlohmann::json event_message_schema(const robdef::MemberDefinition& event, const robdef::TypeLookup& lookup,
                                    std::string_view context_service, std::string_view title);

}  // namespace rr::server::record
