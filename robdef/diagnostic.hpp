// Diagnostics produced by the robdef parser and verifier: one problem in one file at one line.
//
// Message texts follow the official parser/verifier where it has one (robdef.md §11); line numbers
// are always the physical line of the offending statement, member, value or entry (robdef.md §11.2
// recommends this superset of the official information; the official tool often reports 0).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace rr::robdef {

enum class Severity : std::uint8_t { error, warning };

/// What a diagnostic is about. Parse-time kinds come first; tests branch on these.
enum class DiagnosticKind : std::uint8_t {
    syntax,        ///< characters, statement, member, type or constant grammar (robdef.md §1, §4, §6.1, §7)
    ordering,      ///< statement order (robdef.md §2.2) and in-block order (§3.1)
    block,         ///< block structure: end not found / does not match (robdef.md §2.3)
    enumeration,   ///< enum body and values (robdef.md §3.2, §10 rule 8)
    version,       ///< stdver / option version and version-gated features (robdef.md §9)
    deprecated,    ///< legacy `option` keyword (warning)
    name,          ///< invalid or reserved names (robdef.md §8)
    duplicate,     ///< names not unique in their scope (robdef.md §8)
    import,        ///< unknown or recursive imports, duplicate service names (robdef.md §10 rule 3)
    using_alias,   ///< `using` statements (robdef.md §10 rule 7)
    type,          ///< invalid data type or unresolved named type (robdef.md §6.2, §6.3)
    constant,      ///< constant values and struct constants (robdef.md §7)
    member,        ///< member-kind rules: memory, generators, objref targets, parameters (robdef.md §6.3)
    pod,           ///< pod field rules and recursion
    namedarray,    ///< namedarray field rules, element type, recursion
    implements,    ///< `implements` resolution, recursion, inherited types, member matching
    modifier,      ///< member modifiers (warnings, robdef.md §5.2)
};

std::string_view diagnostic_kind_name(DiagnosticKind kind) noexcept;

struct Diagnostic {
    Severity severity = Severity::error;
    DiagnosticKind kind = DiagnosticKind::syntax;
    std::string file;  ///< file name given to the parser (may be empty)
    int line = 0;      ///< 1-based physical line; 0 = whole file / unknown
    std::string message;

    bool is_error() const noexcept { return severity == Severity::error; }
};

/// `file:line: error: message` (or `file: warning: message` when line is 0), as printed by rr-robdef.
std::string format_diagnostic(const Diagnostic& d);

/// True when any diagnostic is an error.
bool has_errors(const std::vector<Diagnostic>& diagnostics) noexcept;

}  // namespace rr::robdef
