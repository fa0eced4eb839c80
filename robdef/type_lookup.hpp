// Lookup of named types across a set of service definitions: what core/value needs to pack and
// unpack structs, pods, namedarrays and enums by name (robdef.md §6.2, §16.3).
#pragma once

#include <string_view>

#include "robdef/service_definition.hpp"

namespace rr::robdef {

/// A named type found by TypeLookup. Exactly one of `entry` / `enumeration` is set when found.
struct NamedTypeRef {
    const ServiceDefinition* service = nullptr;
    const ServiceEntryDefinition* entry = nullptr;  ///< struct, pod, namedarray or object
    const EnumDefinition* enumeration = nullptr;

    explicit operator bool() const noexcept { return service != nullptr; }
};

/// Finds named types. `type_name` is as written in a definition: qualified (`svc.T`, split at the
/// last dot) or unqualified (`T`, meaning a type of `context_service`). Implementations must be
/// thread-compatible (const lookups from many threads).
class TypeLookup {
public:
    virtual ~TypeLookup() = default;
    virtual NamedTypeRef find(std::string_view type_name, std::string_view context_service = {}) const = 0;
};

}  // namespace rr::robdef
