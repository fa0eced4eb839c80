// JSON mapping of RR values, typed by robdef: the rules, with an example for every value kind, are in
// docs/json-mapping.md (the tests run every example of that document).
//
// Summary (T = the robdef type):
//   numeric scalar / T[] / T[N] / T[N-]   number / array of numbers (json_numbers.hpp: 64-bit integers
//                                         beyond 2^53 as decimal strings, "NaN"/"Infinity"/"-Infinity",
//                                         complex as {"re","im"}, bool as true/false)
//   numeric T[*] / T[N,M]                 {"dims":[…], "array":[…]} (column-major)
//   string                                string
//   struct                                object with exactly the struct's fields, or null
//   pod / namedarray                      object of fields; arrays: array of such objects;
//                                         multi-dim: {"dims":[…], "array":[objects]}
//   enum                                  integer (a value name is accepted on input)
//   T{list}                               array, or null
//   T{int32} / T{string}                  object keyed by decimal int32 / by string, or null
//   varvalue                              {"type":"<RR type string>", "value":…}, or null
//   void                                  null
//
// Errors (Result; nlohmann exceptions never escape; the message ends with ` at "<path>"`):
//   DataTypeMismatch  JSON kind (or value kind) differs from what the type needs
//   DataTypeError     wrong length / dims, missing or unknown field, malformed {"dims","array"} or
//                     varvalue object, non-canonical int32 map key, bad type string, invalid UTF-8
//   OutOfRange        number outside the integer type, inexact integer, beyond the single range
//   InvalidArgument   unknown enum value name
//   NullValue         null where the type is not nullable
//   ProtocolError     nested deeper than Limits::max_nesting_depth
#pragma once

#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "base/codec/limits.hpp"
#include "base/error/rr_error.hpp"
#include "core/value/value.hpp"
#include "robdef/service_definition.hpp"
#include "robdef/type_lookup.hpp"

namespace rr {

/// Where value_to_json puts numeric arrays instead of writing them as JSON numbers (the gateway's binary
/// WebSocket pushes, docs/json-api.md "Binary pushes"). Each numeric array (T[], T[N], T[N-], and the
/// items of T[*]; not scalars, not bool) becomes
///   {"$binary": i, "type": "<keyword>", "length": items, "offset": bytes}
/// with its little-endian bytes in blobs[i] (zero-copy: the array's own storage); `offset` is where
/// they start when the blobs are laid out in order, each padded to a multiple of 8 bytes (so every
/// typed view is aligned). A multi-dim array is {"dims": […], "array": {"$binary": …}}. Complex items
/// are re then im; `length` counts items.
struct BinaryArrays {
    std::vector<SharedBytes> blobs;
    std::size_t bytes = 0;  ///< the blobs' size laid out as above (padding included)

    static constexpr std::size_t padded(std::size_t n) noexcept { return (n + 7) & ~std::size_t{7}; }
};

/// `value` as JSON for robdef type `type` (named types resolved through `lookup`, unqualified ones in
/// `context_service`). The value must match the type as for pack_value (pack_value.hpp). With `binary`,
/// numeric arrays go there as described above.
Result<nlohmann::json> value_to_json(const Value& value, const robdef::TypeDefinition& type,
                                     const robdef::TypeLookup& lookup, std::string_view context_service,
                                     const Limits& limits = {}, BinaryArrays* binary = nullptr);

/// The Value of robdef type `type` that `json` denotes. Builds values that pack_value accepts for the
/// same type (scalar pods have one item, struct fields come in definition order).
Result<Value> value_from_json(const nlohmann::json& json, const robdef::TypeDefinition& type,
                              const robdef::TypeLookup& lookup, std::string_view context_service,
                              const Limits& limits = {});

}  // namespace rr
