// Resolving robdef types for packing, unpacking and JSON: named types through a TypeLookup, namedarray
// layouts, and the length rules of array suffixes (robdef.md §6.1–§6.3, wire.md §3.2).
//
// Received definitions are parsed but not verified (robdef.md §16.3), so everything here checks what it
// relies on (recursion, leaf types, lengths) and returns DataTypeError instead of trusting the robdef.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "base/error/rr_error.hpp"
#include "robdef/service_definition.hpp"
#include "robdef/type_lookup.hpp"

namespace rr {

/// A named type found through a TypeLookup.
struct NamedType {
    robdef::NamedTypeKind kind = robdef::NamedTypeKind::unresolved;
    const robdef::ServiceDefinition* service = nullptr;
    const robdef::ServiceEntryDefinition* entry = nullptr;  ///< struct, pod, namedarray, object
    const robdef::EnumDefinition* enumeration = nullptr;
    std::string qualified_name;  ///< `service.Type`
};

/// Resolves `name` (qualified, or unqualified = a type of `context_service`).
/// Errors: DataTypeError when the lookup does not know the name.
Result<NamedType> resolve_named_type(std::string_view name, const robdef::TypeLookup& lookup,
                                     std::string_view context_service);

/// Resolves the named type of `type` (base == namedtype_t): uses `type.qualified_name` when filled,
/// else `type.type_name` in `context_service`.
Result<NamedType> resolve_named_type(const robdef::TypeDefinition& type, const robdef::TypeLookup& lookup,
                                     std::string_view context_service);

/// Shape of one namedarray item: its numeric element type and how many elements it takes.
struct NamedArrayLayout {
    DataTypes element_type = DataTypes::void_t;
    std::size_t elements_per_item = 0;
};

/// Layout of namedarray `type` (kind namedarray). Members must be numeric scalars, fixed arrays, or
/// nested namedarrays (scalar or fixed array), all with one leaf numeric type; at least one element.
/// Errors: DataTypeError for anything else, including recursion.
Result<NamedArrayLayout> namedarray_layout(const NamedType& type, const robdef::TypeLookup& lookup);

/// Length rule of a 1-D array suffix: `[]` → {0, false}; `[N]` → {N, true}; `[N-]` → {N, false}.
/// `[0]`/`[0-]` behave as `[]` (robdef.md §6.1).
struct ArrayLengthRule {
    std::size_t length = 0;  ///< 0 = unbounded
    bool exact = false;
};
ArrayLengthRule array_length_rule(const robdef::TypeDefinition& type) noexcept;

/// Multi-dim with fixed dims (`[N,M]`, `[N,]`): the dims; empty for `[*]`.
std::vector<std::uint32_t> fixed_dims(const robdef::TypeDefinition& type);

/// Product of `dims`, or nullopt-like false on overflow past `max`.
bool dims_product(const std::vector<std::uint32_t>& dims, std::size_t& product,
                  std::size_t max = static_cast<std::size_t>(-1)) noexcept;

/// `type` without its container suffix (`double[]{list}` → `double[]`).
robdef::TypeDefinition without_container(const robdef::TypeDefinition& type);

/// The type of a pod field as it travels inside a pod: multi-dim fields are flattened to a fixed 1-D
/// array of the product of their dims (CORE `pod_field_array`, Python `PackMessageElement_pod`).
robdef::TypeDefinition pod_field_wire_type(const robdef::TypeDefinition& type);

/// The type as robdef text with the named type fully qualified when known (`svc.Pose[2]`), for messages.
std::string type_text(const robdef::TypeDefinition& type, std::string_view qualified_name = {});

}  // namespace rr
