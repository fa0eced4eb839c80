// RR type strings for varvalue: what type a self-describing Value has, named the way the official Python
// client names a received varvalue (robdef.md §17.1), and a parser for such strings.
#pragma once

#include <string>
#include <string_view>

#include "core/error/rr_error.hpp"
#include "core/value/value.hpp"
#include "robdef/service_definition.hpp"

namespace rr {

/// The RR type string of `v` as a varvalue:
///   numeric array  → "double[]", "uint8[]", … (numerics are always arrays in a varvalue)
///   multidim       → "int32[*]"
///   string         → "string"
///   struct         → its qualified type name, "svc.Struct"
///   pod/namedarray → "svc.Pod[]", or "svc.Pod[*]" when multi-dim
///   list / maps    → "varvalue{list}", "varvalue{int32}", "varvalue{string}"
///   enum           → its qualified type name ("int32" when unknown)
///   null           → "" (a null varvalue has no type)
std::string var_type_string(const Value& v);

/// Parses a type string: `BASE [ARRAY] [CONTAINER] [name]` (robdef.md §6.1), e.g. "double[]",
/// "int32[3,2]", "svc.Pose[*]", "varvalue{string}", "string value". BASE is a primitive keyword or a
/// (qualified) named type; `structure`, `object`, `varobject` and `{generator}` are rejected.
/// The result has `base`, `type_name` (named types), array and container fields and `name` filled.
/// Errors: DataTypeError naming the bad text.
Result<robdef::TypeDefinition> parse_type_string(std::string_view text);

/// DataTypes code of a primitive keyword ("double" … "bool", "string", "varvalue", "void"), or
/// namedtype_t for anything else.
DataTypes keyword_data_type(std::string_view word) noexcept;

}  // namespace rr
