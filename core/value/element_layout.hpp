// Building blocks shared by packing and unpacking (wire.md §3.2): element constructors for the fixed
// layouts, count/dims rules of robdef array suffixes, element numbers, and the per-field plan of a pod.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "base/error/rr_error.hpp"
#include "base/message/message.hpp"
#include "core/value/named_type.hpp"
#include "core/value/numeric_array.hpp"

namespace rr {

/// Null: type 0, no data.
MessageElement void_element();
/// string_t with the UTF-8 bytes of `s` (copied).
MessageElement string_element(const std::string& s);
/// Numeric array element named `name` sharing `a`'s bytes.
MessageElement array_element(std::string name, const NumericArray& a);
/// 117 element with children `dims` (uint32[]) and `array` (renamed to "array"); callers retype it to
/// 111/116 with a type name for pods and namedarrays.
MessageElement multidim_element(const std::vector<std::uint32_t>& dims, MessageElement array);

/// Item count `n` against a scalar (`n` must be 1) or a 1-D array suffix (`[N]` exact, `[N-]` at most N).
/// Errors: DataTypeError ("expected 3 items, got 2").
Result<void> check_count(std::size_t n, const robdef::TypeDefinition& t);
/// Multi-dim shape: ≥1 dim, product == `count` (no overflow), and equal to the declared dims when fixed.
/// Errors: DataTypeError.
Result<void> check_dims(const std::vector<std::uint32_t>& dims, std::size_t count, const robdef::TypeDefinition& t);

/// Number of a child of a list / int32 map / pod array: MessageElement::number, else its name when that
/// is a decimal int32 (as CORE's MessageElement_GetElementNumber does); nullopt otherwise.
std::optional<std::int32_t> element_number(const MessageElement& e) noexcept;

/// How one pod field travels (see pod_field_wire_type).
struct PodFieldPlan {
    const robdef::MemberDefinition* member = nullptr;
    robdef::TypeDefinition wire_type;  ///< multi-dim flattened to a fixed 1-D array
    NamedType named;                   ///< resolved pod/namedarray for named fields
    bool multidim = false;             ///< declared multi-dim: the value carries `dims`
    std::vector<std::uint32_t> dims;   ///< declared dims of a multi-dim field
};

/// Plans for every field of pod `pod`, in definition order. Fields must be numeric, pod or namedarray,
/// without containers; multi-dim fields need fixed dims. Errors: DataTypeError (invalid pod definition),
/// or the lookup's error for an unknown nested type.
Result<std::vector<PodFieldPlan>> pod_field_plans(const NamedType& pod, const robdef::TypeLookup& lookup);

}  // namespace rr
