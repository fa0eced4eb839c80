// TypeScript declarations for service definitions (typescript.hpp).
#include "robdef/typescript.hpp"

#include <algorithm>
#include <array>
#include <set>
#include <utility>
#include <vector>

#include "robdef/parser.hpp"

namespace rr::robdef {

namespace {

constexpr int kMaxNesting = 32;

// Words a parameter (a TS binding) cannot be named; robdef forbids only some of them. Property names
// (fields, members, enum values) may be any of these.
bool is_reserved_binding(std::string_view s) {
    static constexpr std::array<std::string_view, 47> kWords{
        "break", "case", "catch", "class", "const", "continue", "debugger", "default", "delete", "do",
        "else", "enum", "export", "extends", "false", "finally", "for", "function", "if", "import",
        "in", "instanceof", "new", "null", "return", "super", "switch", "this", "throw", "true",
        "try", "typeof", "var", "void", "while", "with", "implements", "interface", "let", "package",
        "private", "protected", "public", "static", "yield", "await", "arguments"};
    return std::find(kWords.begin(), kWords.end(), s) != kWords.end();
}

std::string binding_name(std::string_view name) {
    std::string s(name);
    if (is_reserved_binding(s)) s += '_';
    return s;
}

std::string_view scalar_ts(DataTypes t) {
    switch (t) {
        case DataTypes::int64_t: case DataTypes::uint64_t: return "bigint";
        case DataTypes::bool_t: return "boolean";
        case DataTypes::cdouble_t: case DataTypes::csingle_t: return "$rr.Complex";
        default: return "number";
    }
}

// The typed array the package gives for a numeric array (js_numbers.cpp typed_array_name); bool and
// complex arrays are plain arrays of booleans / {real, imag} (numeric_array_to_js).
std::string_view array_ts(DataTypes t) {
    switch (t) {
        case DataTypes::double_t: return "Float64Array";
        case DataTypes::single_t: return "Float32Array";
        case DataTypes::int8_t: return "Int8Array";
        case DataTypes::uint8_t: return "Uint8Array";
        case DataTypes::int16_t: return "Int16Array";
        case DataTypes::uint16_t: return "Uint16Array";
        case DataTypes::int32_t: return "Int32Array";
        case DataTypes::uint32_t: return "Uint32Array";
        case DataTypes::int64_t: return "BigInt64Array";
        case DataTypes::uint64_t: return "BigUint64Array";
        case DataTypes::bool_t: return "boolean[]";
        case DataTypes::cdouble_t: case DataTypes::csingle_t: return "$rr.Complex[]";
        default: return "unknown";
    }
}

// The typed array a namedarray's flat storage has (typed_array_copy: bool → Uint8Array).
std::string_view flat_array_ts(DataTypes t) {
    if (t == DataTypes::bool_t) return "Uint8Array";
    return array_ts(t);
}

// One item of a namedarray's flat storage as the package reads it (flat[i]): a number, a bigint for
// 64-bit elements, {real, imag} for complex ones.
std::string_view flat_item_ts(DataTypes t) {
    switch (t) {
        case DataTypes::int64_t: case DataTypes::uint64_t: return "bigint";
        case DataTypes::cdouble_t: case DataTypes::csingle_t: return "$rr.Complex";
        default: return "number";
    }
}

bool is_64bit(DataTypes t) { return t == DataTypes::int64_t || t == DataTypes::uint64_t; }

// A robdef numeric constant literal as a JS literal: 64-bit values as bigint (`5n`, `0xFFn`).
std::string js_number(std::string_view text, DataTypes t) {
    while (!text.empty() && (text.front() == ' ' || text.front() == '\t')) text.remove_prefix(1);
    while (!text.empty() && (text.back() == ' ' || text.back() == '\t')) text.remove_suffix(1);
    if (!text.empty() && text.front() == '+') text.remove_prefix(1);
    std::string s(text);
    if (is_64bit(t)) s += 'n';
    return s;
}

std::vector<std::string_view> split_commas(std::string_view s) {
    std::vector<std::string_view> out;
    std::size_t start = 0;
    for (std::size_t i = 0; i <= s.size(); ++i)
        if (i == s.size() || s[i] == ',') {
            out.push_back(s.substr(start, i - start));
            start = i + 1;
        }
    return out;
}

std::string trimmed(std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
    return std::string(s);
}

class Generator {
public:
    Generator(const ServiceDefinition& def, const TypeLookup& lookup) : def_(def), lookup_(lookup) {}

    TypeScriptModule run(const TypeScriptOptions& options);

private:
    // A reference to a named type: its own name in this module, `ns.Name` for another definition's.
    std::string named_ref(const TypeDefinition& t);
    // A value of type `t` as the package gives and takes it. Structs, containers and varvalues may be
    // null wherever they occur (a member's value, a field, a list item: to_js gives null for them).
    std::string value_ts(const TypeDefinition& t);
    std::string value_ts_without_container(TypeDefinition t) {
        t.container = ContainerKind::none;
        return value_ts(t);
    }
    // Element type of a namedarray (all its leaves share it), or void_t when unknown.
    DataTypes namedarray_element(const ServiceEntryDefinition& na, int depth = 0) const;
    std::string namedarray_field_ts(const MemberDefinition& f, DataTypes element);
    std::string params_ts(const std::vector<TypeDefinition>& params, std::size_t count);
    // A function member's parameter list and result type (a generator's parameter is the Generator's).
    std::pair<std::string, std::string> function_ts(const MemberDefinition& m);
    std::string member_ts(const MemberDefinition& m);
    // The type of member `m` alone, as $member(name) returns it (a function: an arrow type).
    std::string member_type_ts(const MemberDefinition& m);

    void doc(const std::vector<std::string>& lines, std::string_view indent, const std::vector<std::string>& extra = {});
    void emit_enum(const EnumDefinition& e);
    void emit_entry(const ServiceEntryDefinition& e);
    void emit_constants(const std::vector<ConstantDefinition>& constants, const ServiceEntryDefinition* entry);
    // A constant's value as JS and its type as TS (struct constants inline the constants they name).
    bool constant_js(const ConstantDefinition& c, const ServiceEntryDefinition* entry, std::string& js, std::string& ts,
                     int depth = 0);
    const ConstantDefinition* find_constant(std::string_view name, const ServiceEntryDefinition* entry) const;

    const ServiceDefinition& def_;
    const TypeLookup& lookup_;
    // Text of both forms: the .d.ts (declarations) and the .ts (declarations and values in one module).
    void both(std::string_view text) {
        body_ += text;
        src_ += text;
    }

    std::set<std::string> imported_services_;
    std::string body_;  // .d.ts: declarations after the imports
    std::string src_;   // .ts: the same declarations, constants and enums as values
    std::string js_;    // .js beside the .d.ts: constants and enums as values
};

std::string Generator::named_ref(const TypeDefinition& t) {
    const std::string& q = t.qualified_name;
    auto dot = q.rfind('.');
    if (dot == std::string::npos) return "unknown";
    std::string svc = q.substr(0, dot);
    std::string name = q.substr(dot + 1);
    if (svc == def_.name) return name;
    imported_services_.insert(svc);
    return typescript_namespace_name(svc) + "." + name;
}

std::string Generator::value_ts(const TypeDefinition& t) {
    const std::string null_suffix = " | null";
    if (t.container == ContainerKind::list || t.container == ContainerKind::map_int32 ||
        t.container == ContainerKind::map_string) {
        std::string item = value_ts_without_container(t);
        std::string s = t.container == ContainerKind::list        ? "Array<" + item + ">"
                        : t.container == ContainerKind::map_int32 ? "Map<number, " + item + ">"
                                                                  : "Record<string, " + item + ">";
        return s + null_suffix;
    }
    if (t.container == ContainerKind::generator) return value_ts_without_container(t);
    switch (t.base) {
        case DataTypes::void_t: return "void";
        case DataTypes::string_t: return "string";
        case DataTypes::varvalue_t: return "$rr.VarValue" + null_suffix;
        case DataTypes::varobject_t: return "$rr.ObjectProxy";
        case DataTypes::namedtype_t: {
            std::string ref = named_ref(t);
            switch (t.named_kind) {
                case NamedTypeKind::enumeration:
                case NamedTypeKind::object: return ref;
                case NamedTypeKind::structure: return ref + null_suffix;
                case NamedTypeKind::pod:
                case NamedTypeKind::namedarray:
                    if (t.array == ArrayKind::array) return ref + "[]";
                    if (t.array == ArrayKind::multidimarray) return "$rr.MultiDimArray<" + ref + "[]>";
                    return ref;
                case NamedTypeKind::unresolved: return "unknown";
            }
            return "unknown";
        }
        default: break;
    }
    if (is_numeric(t.base)) {
        if (t.array == ArrayKind::array) return std::string(array_ts(t.base));
        if (t.array == ArrayKind::multidimarray) return "$rr.MultiDimArray<" + std::string(array_ts(t.base)) + ">";
        return std::string(scalar_ts(t.base));
    }
    return "unknown";
}

DataTypes Generator::namedarray_element(const ServiceEntryDefinition& na, int depth) const {
    if (depth > kMaxNesting) return DataTypes::void_t;
    for (const auto& f : na.members) {
        if (f.kind != MemberKind::field) continue;
        if (is_numeric(f.type.base)) return f.type.base;
        if (f.type.base == DataTypes::namedtype_t && f.type.named_kind == NamedTypeKind::namedarray)
            if (auto ref = lookup_.find(f.type.qualified_name); ref && ref.entry)
                return namedarray_element(*ref.entry, depth + 1);
    }
    return DataTypes::void_t;
}

std::string Generator::namedarray_field_ts(const MemberDefinition& f, DataTypes element) {
    if (f.type.base == DataTypes::namedtype_t) {
        std::string ref = named_ref(f.type);
        return f.type.array == ArrayKind::none ? ref : ref + "[]";
    }
    if (f.type.array == ArrayKind::none) return std::string(flat_item_ts(element));
    if (element == DataTypes::cdouble_t || element == DataTypes::csingle_t) return "$rr.Complex[]";
    return std::string(flat_array_ts(element));
}

std::string Generator::params_ts(const std::vector<TypeDefinition>& params, std::size_t count) {
    std::string s;
    for (std::size_t i = 0; i < count && i < params.size(); ++i) {
        if (i) s += ", ";
        s += binding_name(params[i].name) + ": " + value_ts(params[i]);
    }
    return s;
}

std::pair<std::string, std::string> Generator::function_ts(const MemberDefinition& m) {
    if (!m.is_generator()) return {params_ts(m.parameters, m.parameters.size()), "Promise<" + value_ts(m.type) + ">"};
    const bool param_gen = !m.parameters.empty() && m.parameters.back().container == ContainerKind::generator;
    std::size_t n = m.parameters.size() - (param_gen ? 1 : 0);
    std::string ret = value_ts(m.type);
    std::string param = param_gen ? value_ts(m.parameters.back()) : "undefined";
    return {params_ts(m.parameters, n), "Promise<$rr.Generator<" + ret + ", " + param + ">>"};
}

std::string Generator::member_type_ts(const MemberDefinition& m) {
    if (m.kind == MemberKind::function) {
        auto [params, result] = function_ts(m);
        return "(" + params + ") => " + result;
    }
    return member_ts(m).substr(m.name.size() + 2);  // "<name>: <type>"
}

std::string Generator::member_ts(const MemberDefinition& m) {
    const auto dir = m.direction();
    auto directed = [&](std::string_view both, std::string_view ro, std::string_view wo, const std::string& arg) {
        std::string_view name = dir == MemberDirection::readonly ? ro : dir == MemberDirection::writeonly ? wo : both;
        return "$rr." + std::string(name) + "<" + arg + ">";
    };
    switch (m.kind) {
        case MemberKind::property:
            return m.name + ": " + directed("Property", "ReadonlyProperty", "WriteonlyProperty", value_ts(m.type));
        case MemberKind::wire:
            return m.name + ": " + directed("Wire", "ReadonlyWire", "WriteonlyWire", value_ts(m.type));
        case MemberKind::pipe:
            return m.name + ": " + directed("Pipe", "ReadonlyPipe", "WriteonlyPipe", value_ts(m.type));
        case MemberKind::memory: {
            TypeDefinition item = m.type;
            const bool multidim = item.array == ArrayKind::multidimarray;
            item.array = ArrayKind::array;
            item.array_length.clear();
            std::string kind = std::string(dir == MemberDirection::readonly ? "Readonly" : "") +
                               (multidim ? "MultiDimMemory" : "ArrayMemory");
            return m.name + ": $rr." + kind + "<" + value_ts(item) + ">";
        }
        case MemberKind::event: return m.name + ": $rr.Event<[" + params_ts(m.parameters, m.parameters.size()) + "]>";
        case MemberKind::callback:
            return m.name + ": $rr.Callback<(" + params_ts(m.parameters, m.parameters.size()) + ") => " +
                   value_ts(m.type) + ">";
        case MemberKind::objref: {
            TypeDefinition target_type = m.type;  // `T{int32}` / `T[]` name the indexed object type T
            target_type.array = ArrayKind::none;
            target_type.container = ContainerKind::none;
            std::string target = value_ts(target_type);
            switch (objref_index_kind(m.type)) {
                case ObjRefIndexKind::none: return m.name + ": $rr.ObjRef<" + target + ">";
                case ObjRefIndexKind::int32: return m.name + ": $rr.IndexedObjRef<" + target + ", number>";
                case ObjRefIndexKind::string: return m.name + ": $rr.IndexedObjRef<" + target + ", string>";
            }
            return m.name + ": $rr.ObjRef<" + target + ">";
        }
        case MemberKind::function: {
            auto [params, result] = function_ts(m);
            return m.name + "(" + params + "): " + result;
        }
        case MemberKind::field: return m.name + ": " + value_ts(m.type);
    }
    return m.name + ": unknown";
}

void Generator::doc(const std::vector<std::string>& lines, std::string_view indent, const std::vector<std::string>& extra) {
    std::vector<std::string> all;
    for (const auto& l : lines) {
        std::string_view v = l;
        if (!v.empty() && v.front() == ' ') v.remove_prefix(1);
        all.emplace_back(v);
    }
    if (!all.empty() && !extra.empty()) all.emplace_back();
    all.insert(all.end(), extra.begin(), extra.end());
    if (all.empty()) return;
    for (auto& l : all) {  // `*/` would end the comment early
        for (std::size_t p = 0; (p = l.find("*/", p)) != std::string::npos; p += 3) l.replace(p, 2, "*\\/");
        while (!l.empty() && (l.back() == ' ' || l.back() == '\r')) l.pop_back();
    }
    if (all.size() == 1) {
        both(std::string(indent) + "/** " + all[0] + " */\n");
        return;
    }
    both(std::string(indent) + "/**\n");
    for (const auto& l : all) both(std::string(indent) + (l.empty() ? " *" : " * " + l) + "\n");
    both(std::string(indent) + " */\n");
}

void Generator::emit_enum(const EnumDefinition& e) {
    doc(e.docstring, "", {"Enum `" + def_.name + "." + e.name + "`: travels as an int32; the package gives the number."});
    std::string values;
    for (const auto& v : e.values) values += (values.empty() ? "" : " | ") + std::to_string(v.value);
    both("export type " + e.name + " = " + (values.empty() ? "number" : values) + ";\n");
    body_ += "export declare const " + e.name + ": {\n";
    src_ += "export const " + e.name + " = Object.freeze({\n";
    js_ += "export const " + e.name + " = Object.freeze({";
    bool first = true;
    for (const auto& v : e.values) {
        doc(v.docstring, "  ");
        body_ += "  readonly " + v.name + ": " + std::to_string(v.value) + ";\n";
        src_ += "  " + v.name + ": " + std::to_string(v.value) + ",\n";
        js_ += std::string(first ? " " : ", ") + v.name + ": " + std::to_string(v.value);
        first = false;
    }
    body_ += "};\n\n";
    src_ += "} as const);\n\n";
    js_ += " });\n";
}

const ConstantDefinition* Generator::find_constant(std::string_view name, const ServiceEntryDefinition* entry) const {
    if (entry)
        for (const auto& c : entry->constants)
            if (c.name == name) return &c;
    for (const auto& c : def_.constants)
        if (c.name == name) return &c;
    return nullptr;
}

bool Generator::constant_js(const ConstantDefinition& c, const ServiceEntryDefinition* entry, std::string& js,
                            std::string& ts, int depth) {
    if (depth > kMaxNesting) return false;
    const auto& t = c.type;
    if (t.base == DataTypes::string_t) {
        js = trimmed(c.value);  // robdef string constants use JSON escapes, which JS reads the same
        ts = js;
        return true;
    }
    if (is_numeric(t.base) && t.array == ArrayKind::none) {
        js = js_number(c.value, t.base);
        ts = std::string(scalar_ts(t.base));
        return true;
    }
    if (is_numeric(t.base) && t.array == ArrayKind::array) {
        std::string inner = trimmed(c.value);
        if (inner.size() < 2) return false;
        inner = trimmed(std::string_view(inner).substr(1, inner.size() - 2));
        std::string items;
        if (!inner.empty())
            for (auto piece : split_commas(inner)) items += (items.empty() ? "" : ", ") + js_number(piece, t.base);
        ts = std::string(array_ts(t.base));
        js = ts + ".of(" + items + ")";
        return true;
    }
    if (t.base == DataTypes::namedtype_t) {
        auto fields = parse_struct_constant_fields(c.value);
        if (!fields) return false;
        js = "Object.freeze({";
        ts = "{";
        for (std::size_t i = 0; i < fields->size(); ++i) {
            const auto* ref = find_constant((*fields)[i].constant_name, entry);
            std::string fjs, fts;
            if (!ref || !constant_js(*ref, entry, fjs, fts, depth + 1)) return false;
            js += std::string(i ? ", " : " ") + (*fields)[i].name + ": " + fjs;
            ts += std::string(i ? "; " : " ") + "readonly " + (*fields)[i].name + ": " + fts;
        }
        js += fields->empty() ? "})" : " })";
        ts += fields->empty() ? "}" : " }";
        return true;
    }
    return false;
}

void Generator::emit_constants(const std::vector<ConstantDefinition>& constants, const ServiceEntryDefinition* entry) {
    for (const auto& c : constants) {
        std::string js, ts;
        if (!constant_js(c, entry, js, ts)) continue;  // the verifier reported it
        doc(c.docstring, entry ? "  " : "", {"Constant `" + c.type.to_string() + " " + c.name + " " + trimmed(c.value) + "`."});
        if (entry) {
            body_ += "  readonly " + c.name + ": " + ts + ";\n";
            src_ += "  " + c.name + ": " + js + " as " + ts + ",\n";
            js_ += "  " + c.name + ": " + js + ",\n";
        } else {
            body_ += "export declare const " + c.name + ": " + ts + ";\n";
            src_ += "export const " + c.name + ": " + ts + " = " + js + ";\n";
            js_ += "export const " + c.name + " = " + js + ";\n";
        }
    }
}

void Generator::emit_entry(const ServiceEntryDefinition& e) {
    const std::string qualified = def_.name + "." + e.name;
    std::vector<std::string> extra;
    switch (e.kind) {
        case EntryKind::structure: extra.push_back("Struct `" + qualified + "`: a plain object of its fields (or null)."); break;
        case EntryKind::pod: extra.push_back("Pod `" + qualified + "`: a plain object of its fields."); break;
        case EntryKind::namedarray:
            extra.push_back("Namedarray `" + qualified + "`: a plain object of its fields (arrays of them may also be sent as one flat typed array).");
            break;
        case EntryKind::object: {
            std::string s = "Object `" + qualified + "`: `connect<" + e.name + ">(url)` or an objref gives its proxy.";
            extra.push_back(s);
            for (const auto& i : e.implements) extra.push_back("Implements `" + i + "`.");
            break;
        }
    }
    doc(e.docstring, "", extra);
    both("export interface " + e.name + (e.kind == EntryKind::object ? " extends $rr.ObjectBase" : "") + " {\n");
    const DataTypes element = e.kind == EntryKind::namedarray ? namedarray_element(e) : DataTypes::void_t;
    bool then_member = false;
    for (const auto& m : e.members) {
        std::vector<std::string> mextra;
        std::string text = m.type.to_string();
        std::string sig = std::string(member_kind_keyword(m.kind)) + " " + text + " " + m.name;
        if (m.kind == MemberKind::function || m.kind == MemberKind::callback || m.kind == MemberKind::event) {
            sig = std::string(member_kind_keyword(m.kind)) + (m.kind == MemberKind::event ? "" : " " + text) + " " + m.name + "(";
            for (std::size_t i = 0; i < m.parameters.size(); ++i)
                sig += (i ? ", " : "") + m.parameters[i].to_string() + " " + m.parameters[i].name;
            sig += ")";
        }
        for (const auto& mod : m.modifiers) sig += (&mod == &m.modifiers.front() ? " [" : ", ") + mod;
        if (!m.modifiers.empty()) sig += "]";
        mextra.push_back("`" + sig + "`");
        doc(m.docstring, "  ", mextra);
        if (e.kind == EntryKind::namedarray)
            both("  " + m.name + ": " + namedarray_field_ts(m, element) + ";\n");
        else if (e.kind == EntryKind::pod)
            both("  " + m.name + ": " + value_ts(m.type) + ";\n");
        else if (e.kind == EntryKind::object && m.name == "then") {
            // A proxy never has a `then` property (it would be a thenable: `await` would call it); the
            // package gives such a member by $member("then").
            both("  $member(name: \"then\"): " + member_type_ts(m) + ";\n");
            then_member = true;
        } else
            both("  " + member_ts(m) + ";\n");
    }
    if (then_member) both("  $member(name: string): any;\n");
    both("}\n");
    if (!e.constants.empty()) {
        both("/** Constants of `" + qualified + "`. */\n");
        body_ += "export declare const " + e.name + ": {\n";
        src_ += "export const " + e.name + " = Object.freeze({\n";
        js_ += "export const " + e.name + " = Object.freeze({\n";
        emit_constants(e.constants, &e);
        body_ += "};\n";
        src_ += "});\n";
        js_ += "});\n";
    }
    both("\n");
}

TypeScriptModule Generator::run(const TypeScriptOptions& options) {
    std::vector<std::string> extra;
    if (def_.stdver) extra.push_back("stdver " + def_.stdver->to_string());
    doc(def_.docstring, "", extra);
    if (!body_.empty()) both("\n");
    emit_constants(def_.constants, nullptr);
    if (!def_.constants.empty()) both("\n");
    for (const auto& e : def_.enums) emit_enum(e);
    for (const auto& ex : def_.exceptions) {
        doc(ex.docstring, "", {"Exception `" + def_.name + "." + ex.name + "`: an RRError with this errorName."});
        both("export type " + ex.name + "Name = \"" + def_.name + "." + ex.name + "\";\n\n");
    }
    for (const auto* list : {&def_.structures, &def_.pods, &def_.namedarrays, &def_.objects})
        for (const auto& e : *list) emit_entry(e);

    TypeScriptModule out;
    out.file_stem = def_.name;
    std::string head = "// Generated by `rr-robdef ts` from service definition " + def_.name +
                       ": the types the robotraconteur-wasm package gives and takes. Do not edit.\n";
    head += "import type * as $rr from \"" + options.package + "\";\n";
    for (const auto& svc : imported_services_)
        head += "import type * as " + typescript_namespace_name(svc) + " from \"./" + svc + ".js\";\n";
    out.declarations = head + "\n" + body_;
    // The .ts imports only what it uses: an unused import fails builds with noUnusedLocals.
    std::string src_head = "// Generated by `rr-robdef ts` from service definition " + def_.name +
                           ": the types the robotraconteur-wasm package gives and takes, its enums and constants as values. Do not edit.\n";
    if (src_.find("$rr.") != std::string::npos) src_head += "import type * as $rr from \"" + options.package + "\";\n";
    for (const auto& svc : imported_services_)
        src_head += "import type * as " + typescript_namespace_name(svc) + " from \"./" + svc + ".js\";\n";
    out.source = src_head + "\n" + src_;
    for (auto* text : {&out.declarations, &out.source})
        while (text->size() > 1 && text->back() == '\n' && (*text)[text->size() - 2] == '\n') text->pop_back();
    if (src_.empty()) out.source += "export {};\n";
    out.javascript = "// Generated by `rr-robdef ts` from service definition " + def_.name +
                     ": its enums and constants (the types are in the .d.ts). Do not edit.\n" +
                     (js_.empty() ? std::string("export {};\n") : js_);
    return out;
}

}  // namespace

std::string typescript_namespace_name(std::string_view service_name) {
    std::string s(service_name);
    std::replace(s.begin(), s.end(), '.', '_');
    return s;
}

TypeScriptModule to_typescript(const ServiceDefinition& def, const TypeLookup& lookup, const TypeScriptOptions& options) {
    return Generator(def, lookup).run(options);
}

}  // namespace rr::robdef
