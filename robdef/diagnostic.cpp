#include "robdef/diagnostic.hpp"

namespace rr::robdef {

std::string_view diagnostic_kind_name(DiagnosticKind kind) noexcept {
    switch (kind) {
        case DiagnosticKind::syntax: return "syntax";
        case DiagnosticKind::ordering: return "ordering";
        case DiagnosticKind::block: return "block";
        case DiagnosticKind::enumeration: return "enumeration";
        case DiagnosticKind::version: return "version";
        case DiagnosticKind::deprecated: return "deprecated";
        case DiagnosticKind::name: return "name";
        case DiagnosticKind::duplicate: return "duplicate";
        case DiagnosticKind::import: return "import";
        case DiagnosticKind::using_alias: return "using";
        case DiagnosticKind::type: return "type";
        case DiagnosticKind::constant: return "constant";
        case DiagnosticKind::member: return "member";
        case DiagnosticKind::pod: return "pod";
        case DiagnosticKind::namedarray: return "namedarray";
        case DiagnosticKind::implements: return "implements";
        case DiagnosticKind::modifier: return "modifier";
    }
    return "unknown";
}

std::string format_diagnostic(const Diagnostic& d) {
    std::string s = d.file.empty() ? std::string("<text>") : d.file;
    if (d.line > 0) {
        s += ':';
        s += std::to_string(d.line);
    }
    s += d.severity == Severity::error ? ": error: " : ": warning: ";
    s += d.message;
    return s;
}

bool has_errors(const std::vector<Diagnostic>& diagnostics) noexcept {
    for (const auto& d : diagnostics)
        if (d.is_error()) return true;
    return false;
}

}  // namespace rr::robdef
