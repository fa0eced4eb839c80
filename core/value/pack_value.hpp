// Packing values into message elements and back, typed by robdef, exactly as CORE lays them out
// (wire.md §3.2; CORE DataTypesPacking.h, ServiceStructure.h; Python PythonTypeSupport.cpp).
//
// Element layout per type (`name` = element_name, children listed as name:type):
//   numeric T / T[] / T[N] / T[N-]   T-array element (1–14, 14 = bool), scalar = 1 item
//   numeric T[*] / T[N,M]            117 { dims:uint32[] (≥1 entry), array:T[] (column-major) }
//   string                           11, UTF-8 bytes (empty string = 0 items, not void)
//   enum                             int32 (7) scalar
//   struct S                         101 "svc.S" { one child per field, by field name, definition order }
//   pod P / P[] / P[N] / P[N-]       110 "svc.P" { #0..#n-1: 109 "" { one child per field } }
//   pod P[*] / P[N,M]                111 "svc.P" { dims:uint32[], array:110 "svc.P" {…} }
//   namedarray A / A[] / A[N]        115 "svc.A" { array:E[] (items stacked, E = element type) }
//   namedarray A[*] / A[N,M]         116 "svc.A" { dims:uint32[], array:115 "svc.A" {…} }
//   T{list}                          108 { #0..#n-1 } (#k = MessageElement::number k)
//   T{int32}                         102 { #key … }
//   T{string}                        103 { key … }
//   varvalue                         the concrete type of the value (var_type.hpp)
//   null                             0 (void), no data — allowed for structs, containers and varvalue only
// Inside pods, multi-dim fields travel flattened as fixed 1-D arrays (T-array, 110 or 115 with the
// product of the dims as count), as CORE's pod_field_array and Python's pod packer do.
//
// Errors (message names the path, e.g. `at "pose.position[2]"`, and the expected RR type):
//   DataTypeMismatch  value kind, numeric type, or type name differs from the robdef type
//   DataTypeError     wrong count for a scalar/[N]/[N-]/fixed dims, missing/unknown field, duplicate map key,
//                     unknown named type, invalid type for a value (object, generator, string[]…)
//   NullValue         null where the type is not nullable (numerics, strings, enums, pods, namedarrays)
//   ProtocolError     value nested deeper than Limits::max_nesting_depth
#pragma once

#include <string_view>

#include "base/codec/limits.hpp"
#include "base/error/rr_error.hpp"
#include "base/message/message.hpp"
#include "core/value/value.hpp"
#include "robdef/service_definition.hpp"
#include "robdef/type_lookup.hpp"

namespace rr {

/// Packs `value` as robdef type `type` into an element named `element_name`. Named types in `type` are
/// resolved through `lookup`; unqualified names belong to `context_service`. Numeric data is shared with
/// the value, not copied.
Result<MessageElement> pack_value(const Value& value, const robdef::TypeDefinition& type,
                                  std::string_view element_name, const robdef::TypeLookup& lookup,
                                  std::string_view context_service);
Result<MessageElement> pack_value(const Value& value, const robdef::TypeDefinition& type,
                                  std::string_view element_name, const robdef::TypeLookup& lookup,
                                  std::string_view context_service, const Limits& limits);

/// Unpacks `element` as robdef type `type`. Numeric arrays of more than one item are zero-copy views of
/// the element's data (they keep its buffer alive). Struct fields are found by name (order is free); extra
/// children are ignored, as CORE does. Additional errors: MessageElementNotFound for a missing struct/pod
/// field or multi-dim `dims`/`array` child; DataTypeError for list children not numbered 0..n-1 in order,
/// int32-map children without a number, duplicate map keys, dims product ≠ item count.
Result<Value> unpack_value(const MessageElement& element, const robdef::TypeDefinition& type,
                           const robdef::TypeLookup& lookup, std::string_view context_service);
Result<Value> unpack_value(const MessageElement& element, const robdef::TypeDefinition& type,
                           const robdef::TypeLookup& lookup, std::string_view context_service,
                           const Limits& limits);

/// Unpacks `element` as a varvalue without any robdef: structs keep the fields present (each unpacked as
/// a varvalue), pods keep the fields of their items (all items must have the same field names), and
/// namedarrays keep their flat array. Numeric values are arrays (scalar-ness is unknown).
Result<Value> unpack_value_untyped(const MessageElement& element, const Limits& limits = {});

}  // namespace rr
