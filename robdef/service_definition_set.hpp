// A set of service definitions that belong together (a node's registered types, or the definitions a
// client pulled from one service): owns them, always contains the built-in
// RobotRaconteurServiceIndex (robdef.md §13), resolves named types (robdef.md §6.2, §16.3) and
// verifies the set (robdef.md §10).
#pragma once

#include <memory>
#include <string_view>
#include <vector>

#include "base/error/rr_error.hpp"
#include "robdef/diagnostic.hpp"
#include "robdef/service_definition.hpp"
#include "robdef/type_lookup.hpp"

namespace rr::robdef {

/// Not thread-safe for mutation; const member functions may be called from many threads.
class ServiceDefinitionSet : public TypeLookup {
public:
    /// A set holding only the built-in RobotRaconteurServiceIndex.
    ServiceDefinitionSet();
    ServiceDefinitionSet(ServiceDefinitionSet&&) noexcept = default;
    ServiceDefinitionSet& operator=(ServiceDefinitionSet&&) noexcept = default;

    /// Parses `text` and adds it (see add). Returns the parse warnings; error: the parse error
    /// (ServiceDefinitionError, message `<file>:<line>: <text>`), the set is unchanged then.
    Result<std::vector<Diagnostic>> add_text(std::string_view text, std::string_view file_name);

    /// Adds a parsed definition. One with the same service name replaces the earlier one (pointers
    /// to the replaced definition become invalid; others stay valid). Named types of every
    /// definition are then re-resolved: TypeDefinition::named_kind and qualified_name are filled
    /// for each member, parameter and return type that names a type found in the set (qualified
    /// names against any service in the set, unqualified ones against the member's own service,
    /// then its `using` aliases); types not found keep NamedTypeKind::unresolved.
    const ServiceDefinition& add(ServiceDefinition def);

    /// Verifies all definitions as one set (robdef.md §10), the built-in included.
    std::vector<Diagnostic> verify() const;

    /// Definition with this service name, or nullptr.
    const ServiceDefinition* find_service(std::string_view service_name) const noexcept;

    /// TypeLookup: `svc.T` (split at the last dot) or `T` within `context_service`.
    NamedTypeRef find(std::string_view type_name, std::string_view context_service = {}) const override;

    /// All definitions in insertion order (the built-in first).
    std::vector<const ServiceDefinition*> definitions() const;
    std::size_t size() const noexcept { return defs_.size(); }

private:
    void resolve_all();
    std::vector<std::unique_ptr<ServiceDefinition>> defs_;
};

/// Fills named_kind / qualified_name of every named type in `def` using `lookup` (what
/// ServiceDefinitionSet::add does for each of its definitions).
void resolve_named_types(ServiceDefinition& def, const TypeLookup& lookup);

}  // namespace rr::robdef
