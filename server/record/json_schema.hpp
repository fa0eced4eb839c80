// JSON Schema (draft 2020-12) of the gateway's JSON mapping (docs/json-mapping.md) for robdef types:
// what a recording's `json` channels declare as their schema, so that Foxglove / Lichtblick (and any
// JSON Schema validator) know the fields of each message without the service definition.
//
// The schemas keep to the subset of JSON Schema that Foxglove's / Lichtblick's channel parser reads
// (docs/recording.md "Opening a recording in Foxglove or Lichtblick"): one `type` per property, objects
// with `properties`, array items of one non-array type, named types inlined (no "$ref"; a struct inside
// itself is an object without fields). Values that subset cannot describe (void, objrefs, unknown types,
// lists of arrays, a varvalue's value) are left out of `properties` and named in the object's
// description. Values the JSON mapping writes as strings (non-finite floats, integers beyond 2^53) or
// null (a null struct, list, map or varvalue) are described, not declared: such a message does not
// validate against its schema.
#pragma once

#include <string_view>

#include <nlohmann/json.hpp>

#include "robdef/service_definition.hpp"
#include "robdef/type_lookup.hpp"

namespace rr::server::record {

/// Schema of one value of `type` as the JSON mapping writes it, named types resolved through `lookup`
/// (unqualified names in `context_service`) and inlined; null when the subset cannot describe it.
nlohmann::json value_schema(const robdef::TypeDefinition& type, const robdef::TypeLookup& lookup,
                            std::string_view context_service);

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
