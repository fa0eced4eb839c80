// JSON text written straight from a message element, for the gateway's hot path (a wire value or an
// event rendered once for all its JSON subscribers): the same text as json_text(value_to_json(
// unpack_value(…))) (nlohmann's compact dump), without the Value and nlohmann::json trees in between
// (issue 14: about 38 allocations per value that way; one string here).
//
// Covers the types that carry streams of numbers: numeric scalars and numeric T[], T[N], T[N-] of every
// numeric type (bool and complex included), mapped as docs/json-mapping.md §Numbers says. Anything else
// (strings, named types, containers, multi-dim arrays, varvalue, void) and any element that does not
// match its type are left to the general path, which also words the error.
#pragma once

#include <string>

#include "base/message/message.hpp"
#include "robdef/service_definition.hpp"

namespace rr::element_json_text {

/// True when append() renders values of `type` (an element may still not match it).
bool renders(const robdef::TypeDefinition& type) noexcept;

/// Appends the JSON text of `element` as robdef type `type` to `out` and returns true; returns false
/// with `out` unchanged when renders(type) is false or the element does not match the type (element
/// type, byte count, item count: the cases where unpack_value fails). Never throws but std::bad_alloc.
bool append(std::string& out, const MessageElement& element, const robdef::TypeDefinition& type);

/// Appends the JSON text of one item of numeric type `type` stored little-endian at `item` (any
/// alignment), as append() writes each item. `type` must be numeric.
void append_number(std::string& out, DataTypes type, const std::byte* item);

}  // namespace rr::element_json_text
