// Canonical text form of a service definition (robdef.md §12): what dynamic (Python) servers send
// and what dynamic clients re-serialise received definitions into. Comments, docstrings and
// `end <kind>` forms are dropped; entries are regrouped by kind (structs, pods, namedarrays,
// objects) in source order; bodies use 4-space indentation; LF line endings.
//
// One deliberate difference from the official ToString: top-level `option` lines of a definition
// with `stdver` >= 0.9.2 (legal only above the stdver line, robdef.md §2.2) are written between the
// `service` and `stdver` lines. The official ToString writes them after the usings, where its own
// parser rejects them; we never emit text the official parser rejects.
#pragma once

#include <string>

#include "robdef/service_definition.hpp"

namespace rr::robdef {

/// Canonical text of `def`. Qualified type names are written back through `using` aliases;
/// `[0]`/`[0-]` come out as `[]`. parse_service_definition(to_string(d)) gives back an
/// equivalent definition (round trip is stable after one pass).
std::string to_string(const ServiceDefinition& def);

/// One member line without indentation, e.g. `function double f(int32 a, double[] b) [urgent]`.
/// `in_object` selects `property` vs `field` for value members.
std::string member_to_string(const MemberDefinition& m, const ServiceDefinition& def, bool in_object);

}  // namespace rr::robdef
