// RR type strings for varvalue: what type a self-describing Value has, named the way the official Python
// client names a received varvalue (robdef.md §17.1), and a parser for such strings.
#pragma once

#include <string>
#include <string_view>

#include "base/error/rr_error.hpp"
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

/// Parses the type string of a value: robdef::parse_type (`BASE [ARRAY] [CONTAINER] [name]`, robdef.md
/// §6.1, e.g. "double[]", "int32[3,2]", "svc.Pose[*]", "varvalue{string}", "string value"), then rejects
/// what cannot be a value: `structure`, `object`, `varobject`, `{generator}`, void arrays/containers.
/// Named types stay unresolved. Errors: DataTypeError naming the bad text.
Result<robdef::TypeDefinition> parse_type_string(std::string_view text);

}  // namespace rr
