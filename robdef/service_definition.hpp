// The service definition type model: what the parser produces, the verifier checks, and the value
// layer (core/value) and sessions use to pack, unpack and dispatch.
//
// Grammar and semantics: ../shared/protocol/robdef.md (§2–§9), robotraconteur_standards
// draft/service_defintion.md. Names follow CORE's ServiceDefinition.h where they exist.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "base/message/data_types.hpp"

namespace rr::robdef {

/// Where a definition element came from (1-based line; 0 = unknown).
struct SourceLocation {
    std::string file;
    int line = 0;
};

/// Array suffix of a type token (robdef.md §6.1).
enum class ArrayKind : std::uint8_t {
    none,
    array,          ///< `[]`, `[N]`, `[N-]`
    multidimarray,  ///< `[*]`, `[N,]`, `[N,M,…]`
};

/// Container suffix of a type token (robdef.md §6.1).
enum class ContainerKind : std::uint8_t { none, list, map_int32, map_string, generator };

/// Kind of a resolved named type.
enum class NamedTypeKind : std::uint8_t { unresolved, structure, pod, namedarray, enumeration, object };

/// A type as written in a robdef, e.g. `double[3]{list} x` (robdef.md §6).
///
/// `base` is the primitive code (double_t … bool_t, string_t, varvalue_t, varobject_t, object_t,
/// structure_t, void_t) or namedtype_t for a named type, whose name is in `type_name` exactly as written
/// after `using` expansion (qualified `a.b.T`, or unqualified `T` meaning the defining service).
/// Array: `array_length` holds the written dimensions: `[]` → {} var; `[N]` → {N} fixed; `[N-]` → {N}
/// var (max N); `[*]` → {} var; `[N,M]` → {N,M} fixed; `[0]`/`[0-]` behave as `[]` (robdef.md §6.1).
struct TypeDefinition {
    std::string name;  ///< parameter/field name where a name follows the type; else empty
    DataTypes base = DataTypes::void_t;
    std::string type_name;  ///< named types only
    ArrayKind array = ArrayKind::none;
    bool array_var_length = false;
    std::vector<std::int32_t> array_length;
    ContainerKind container = ContainerKind::none;

    /// Filled by resolution: the kind of named type and its fully qualified name (`svc.T`).
    NamedTypeKind named_kind = NamedTypeKind::unresolved;
    std::string qualified_name;

    /// The type token as robdef text (`double[3]{list}`), without the name; uses `type_name` as
    /// written (not the qualified name).
    std::string to_string() const;

    bool is_void() const noexcept {
        return base == DataTypes::void_t && array == ArrayKind::none && container == ContainerKind::none;
    }
};

enum class MemberKind : std::uint8_t { field, property, function, event, objref, pipe, callback, wire, memory };

/// robdef keyword for a member kind (`property`, `function`, …).
std::string_view member_kind_keyword(MemberKind kind) noexcept;

/// `word` with its indefinite article, for messages: "a wire", "an event", "an objref".
std::string with_article(std::string_view word);

/// Direction from modifiers: readonly wins over writeonly (robdef.md §5.2).
enum class MemberDirection : std::uint8_t { both, readonly, writeonly };

/// One member of a struct/pod/namedarray (kind == field) or of an object.
/// property/field/objref/pipe/wire/memory: `type` is the value type (named "value" for the verifier).
/// function/callback: `type` is the return type; `parameters` the parameters.
/// event: `parameters` only.
struct MemberDefinition {
    MemberKind kind = MemberKind::property;
    std::string name;
    TypeDefinition type;
    std::vector<TypeDefinition> parameters;
    std::vector<std::string> modifiers;  ///< trimmed text of each modifier, in order
    std::vector<std::string> docstring;  ///< `##` lines, without the `##`
    SourceLocation location;

    MemberDirection direction() const noexcept;
    bool has_modifier(std::string_view m) const noexcept;
    /// Function whose return or last parameter is `{generator}` (robdef.md §6.3).
    bool is_generator() const noexcept;
};

struct ConstantDefinition {
    std::string name;
    TypeDefinition type;
    std::string value;  ///< value text as written (hex stays hex)
    std::vector<std::string> docstring;
    SourceLocation location;
};

struct EnumValue {
    std::string name;
    std::int32_t value = 0;
    bool hex = false;       ///< written in hex (for to_string)
    bool implicit = false;  ///< value not written; previous + 1
    std::vector<std::string> docstring;
    int line = 0;  ///< physical line of the value (added: diagnostics); 0 = unknown
};

struct EnumDefinition {
    std::string name;
    std::vector<EnumValue> values;
    std::vector<std::string> docstring;
    SourceLocation location;
};

struct ExceptionDefinition {
    std::string name;
    std::vector<std::string> docstring;
    SourceLocation location;
};

/// `using a.b.T` or `using a.b.T as U`.
struct UsingDefinition {
    std::string qualified_name;
    std::string unqualified_name;  ///< alias (defaults to the last segment)
    SourceLocation location;
};

enum class EntryKind : std::uint8_t { structure, pod, namedarray, object };

/// A struct, pod, namedarray or object.
struct ServiceEntryDefinition {
    EntryKind kind = EntryKind::structure;
    std::string name;
    std::vector<MemberDefinition> members;
    std::vector<std::string> implements;  ///< as written after using expansion
    std::vector<ConstantDefinition> constants;
    std::vector<std::string> options;     ///< legacy `option` lines (text after `option `)
    std::vector<std::string> docstring;
    SourceLocation location;
    /// Added for diagnostics: physical line of each `implements` / `option` line, parallel to
    /// `implements` / `options` when filled by the parser (may be shorter for hand-built models).
    std::vector<int> implements_lines;
    std::vector<int> option_lines;

    const MemberDefinition* find_member(std::string_view member_name) const noexcept;
};

/// The key an objref member takes in a service path (`name[key]`, robdef.md §4.1): none for
/// `objref T`; an int32 for `T[]` and `T{int32}` (the official generated code takes `int32_t`); a
/// string for `T{string}`. With both an array and a container (`T[]{int32}`, which the official
/// parser accepts by mistake) the container decides, and `T[]{list}` / `T[]{generator}` take an int32
/// as `T[]` does. Official dynamic clients send any key as its text.
enum class ObjRefIndexKind : std::uint8_t { none, int32, string };
ObjRefIndexKind objref_index_kind(const TypeDefinition& objref_type) noexcept;

/// Pipe reliability (robdef.md §5.2): the `unreliable` modifier, or the legacy object option line
/// `option pipe <name> unreliable`. Added helper.
bool pipe_is_unreliable(const ServiceEntryDefinition& entry, const MemberDefinition& pipe) noexcept;

/// Standard version from `stdver` or legacy `option version` (robdef.md §9).
struct Version {
    std::uint32_t major = 0, minor = 0, patch = 0, tweak = 0;
    friend auto operator<=>(const Version&, const Version&) = default;
    std::string to_string() const;  ///< `a.b`, `a.b.c` or `a.b.c.d`, trailing zeros dropped
};

/// One parsed service definition file.
struct ServiceDefinition {
    std::string name;
    std::optional<Version> stdver;
    bool version_from_option = false;  ///< version came from legacy `option version`
    std::vector<std::string> imports;
    std::vector<UsingDefinition> usings;
    std::vector<std::string> options;
    std::vector<ConstantDefinition> constants;
    std::vector<EnumDefinition> enums;
    std::vector<ExceptionDefinition> exceptions;
    std::vector<ServiceEntryDefinition> structures;
    std::vector<ServiceEntryDefinition> pods;
    std::vector<ServiceEntryDefinition> namedarrays;
    std::vector<ServiceEntryDefinition> objects;
    std::vector<std::string> docstring;
    SourceLocation location;  ///< file, line of the `service` statement
    /// Added for diagnostics: physical line of each `import` / top-level `option` line, parallel to
    /// `imports` / `options` when filled by the parser, and of the version statement (0 = none).
    std::vector<int> import_lines;
    std::vector<int> option_lines;
    int version_line = 0;

    /// Struct/pod/namedarray/object with this unqualified name, or nullptr.
    const ServiceEntryDefinition* find_entry(std::string_view entry_name) const noexcept;
    const EnumDefinition* find_enum(std::string_view enum_name) const noexcept;
    const ExceptionDefinition* find_exception(std::string_view exception_name) const noexcept;
};

}  // namespace rr::robdef
