// Parser for service definition text (robdef.md §1–§9): one `.robdef` text in, one
// ServiceDefinition out. Sans-IO: the caller reads files and hands their bytes to
// definition_file_text() (a leading UTF-8 BOM dropped with a warning, robdef.md §1.1).
//
// Accepts stdver 0.9 / 0.10 files and the legacy forms without stdver (`option`, `option version`,
// `option constant`, `option pipe X unreliable`, `end struct` / `end object`), LF and CRLF, line
// continuations, comments and docstrings. The first problem stops parsing (as in the official
// parser); `option` deprecation is a warning. Semantic checks live in verifier.hpp.
//
// Deliberate differences from the official parser (robdef.md §20 lists the quirks):
//  - line numbers are physical lines (no drift after continuations, robdef.md §1.2; enum errors at
//    the offending value, not at `end`; member and type errors at the member line, not 0/-1);
//  - array sizes above 2^31-1 give `Could not parse type "…"` (the official text leaks
//    `Parse error: bad lexical cast: …`);
//  - modifier arguments may have blanks before any comma (`f(1 ,2 ,3)`);
//  - `[0]`/`[0-]` are stored as `[]` (the official parser keeps a fixed length 0 that behaves as `[]`).
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "base/error/rr_error.hpp"
#include "robdef/diagnostic.hpp"
#include "robdef/service_definition.hpp"

namespace rr::robdef {

/// The UTF-8 byte-order mark, EF BB BF. Not ASCII: the parser refuses it anywhere in a text, naming it
/// (as the official ServiceDefinition::FromString refuses it, with the same message before the name).
inline constexpr std::string_view kUtf8ByteOrderMark = "\xEF\xBB\xBF";

/// The text of a definition file, and what reading it noticed.
struct FileText {
    std::string text;
    std::vector<Diagnostic> diagnostics;  ///< at most a warning about a dropped byte-order mark
};

/// The bytes of a `.robdef` file as the official file readers take them (robdef.md §1.1): one leading
/// UTF-8 byte-order mark is dropped, as RobotRaconteurGen's reader and the Python library's
/// ReadServiceDefinitionFile (utf-8-sig) drop it, with a warning (line 1) that names it, because the
/// same text registered as text (RegisterServiceType) or sent by a service is refused. Anything else
/// (a second mark, one after a blank line) stays and is refused by the parser.
FileText definition_file_text(std::string bytes, std::string_view file_name);

struct ParseOutput {
    ServiceDefinition definition;
    std::vector<Diagnostic> warnings;  ///< `option keyword is deprecated` (robdef.md §2.2)
};

/// Parses one definition. Error: ServiceDefinitionError whose message is
/// `<file>:<line>: <message>` (see parse_service_definition_report for the structured form).
Result<ParseOutput> parse_service_definition(std::string_view text, std::string_view file_name);

/// Same parse, with the failure as a Diagnostic (file, line, kind, official message text).
struct ParseReport {
    std::optional<ServiceDefinition> definition;  ///< set when parsing succeeded
    std::vector<Diagnostic> diagnostics;          ///< warnings, then the error if any
    bool ok() const noexcept { return definition.has_value(); }
};
ParseReport parse_service_definition_report(std::string_view text, std::string_view file_name);

/// Parses a type token alone, optionally followed by a name: `double[3]{list}`, `svc.Pod[*]`,
/// `varvalue{string}`, `int32 x` (robdef.md §6.1). Named types are kept as written (no `using`
/// expansion, unresolved). Error: ServiceDefinitionError `Could not parse type "…"`.
Result<TypeDefinition> parse_type(std::string_view text);

/// True when `value` is a valid constant value for `type` (robdef.md §7). Integer ranges are the
/// type's full range except for int8/uint8, which take exactly one digit `0`-`9` per value as in the
/// official parser (it converts them as characters; robdef.md §7); unsigned types also take negative
/// decimal values, as the official parser does.
bool is_valid_constant_value(const TypeDefinition& type, std::string_view value);

/// One `field: constant` pair of a struct constant.
struct StructConstantField {
    std::string name;
    std::string constant_name;
};
/// Fields of a struct constant value `{a: c1, b: c2}` / `{}`; nullopt when malformed.
std::optional<std::vector<StructConstantField>> parse_struct_constant_fields(std::string_view value);

}  // namespace rr::robdef
