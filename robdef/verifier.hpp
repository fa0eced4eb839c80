// Verifier for a set of parsed service definitions (robdef.md §10): imports resolved across the
// set, names and reserved words, using, enums, constants (incl. struct constants), pods and
// namedarrays (field rules and recursion), memory rules, generators, objref targets, implements
// (inherited types, exact member matching), and version rules.
//
// Unlike the official verifier, which stops at the first error, this one reports every error it
// can find (one per offending statement/member), with the official message texts and the physical
// line of the offending statement (robdef.md §11). Warnings (`Unknown member modifier: …`,
// `Could not verify modifier parameters: …`, `Invalid member modifier combination: …`) are
// returned in the same list with Severity::warning. Parse-time warnings are not repeated here.
//
// Differences from the official verifier: all errors are reported (not only the first); two
// definitions with the same service name are an error (`… is defined more than once`); implements
// cycles that do not pass through the object being verified are reported instead of recursing
// forever; an inherited type missing from a base object's own list is reported when that base is
// verified (once), not again for every object implementing it; errors from legacy
// `option constant` lines inside an entry are reported at the entry's line, as the official tool
// does (the seed examples' verdicts expect it), although ServiceEntryDefinition::option_lines has
// the option's own line.
#pragma once

#include <span>
#include <vector>

#include "robdef/diagnostic.hpp"
#include "robdef/service_definition.hpp"

namespace rr::robdef {

/// The official library version we follow (the `robotraconteur` package pinned in
/// test/interop/requirements.txt); a definition declaring a newer standard version fails with
/// `Service <svc> requires newer version of Robot Raconteur` (robdef.md §9).
inline constexpr Version kLibraryVersion{1, 2, 9, 0};

/// Verifies `defs` as one set: every import must name a definition in the set. The built-in
/// RobotRaconteurServiceIndex is not added here (ServiceDefinitionSet adds it).
/// Definitions are not modified; see ServiceDefinitionSet for resolution of named types.
std::vector<Diagnostic> verify_service_definitions(std::span<const ServiceDefinition> defs);
std::vector<Diagnostic> verify_service_definitions(std::span<const ServiceDefinition* const> defs);

}  // namespace rr::robdef
