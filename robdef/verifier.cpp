// Verification rules of robdef.md §10, in the official order, reporting every error found.
#include "robdef/verifier.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <map>
#include <set>
#include <string>

#include "robdef/lexer.hpp"
#include "robdef/parser.hpp"

namespace rr::robdef {
namespace {

constexpr Version kVersion0_9{0, 9, 0, 0};

constexpr std::array<std::string_view, 40> kReservedNames{
    "object",   "end",      "option",    "service",   "struct",   "import",   "implements", "field",
    "property", "function", "event",     "objref",    "pipe",     "callback", "wire",       "memory",
    "void",     "int8",     "uint8",     "int16",     "uint16",   "int32",    "uint32",     "int64",
    "uint64",   "single",   "double",    "varvalue",  "varobject", "exception", "using",    "constant",
    "enum",     "pod",      "namedarray", "cdouble",  "csingle",  "bool",     "stdver",     "string"};

bool starts_with_ci(std::string_view s, std::string_view prefix) {
    if (s.size() < prefix.size()) return false;
    for (std::size_t i = 0; i < prefix.size(); ++i)
        if (std::tolower(static_cast<unsigned char>(s[i])) != prefix[i]) return false;
    return true;
}

std::string quoted(std::string_view s) { return "\"" + std::string(s) + "\""; }

/// A named type found during verification.
struct Found {
    const ServiceDefinition* service = nullptr;
    const ServiceEntryDefinition* entry = nullptr;
    const EnumDefinition* enumeration = nullptr;
    explicit operator bool() const { return service != nullptr; }
    /// DataTypes code of the named type (structure_t, pod_t, namedarray_t, object_t, enum_t).
    DataTypes code() const {
        if (enumeration) return DataTypes::enum_t;
        switch (entry->kind) {
            case EntryKind::structure: return DataTypes::structure_t;
            case EntryKind::pod: return DataTypes::pod_t;
            case EntryKind::namedarray: return DataTypes::namedarray_t;
            case EntryKind::object: return DataTypes::object_t;
        }
        return DataTypes::void_t;
    }
    std::string qualified() const {
        return service->name + "." + (enumeration ? enumeration->name : entry->name);
    }
};

Found find_in_service(const ServiceDefinition& s, std::string_view name) {
    for (const auto* list : {&s.structures, &s.pods, &s.namedarrays, &s.objects})
        for (const auto& e : *list)
            if (e.name == name) return Found{&s, &e, nullptr};
    for (const auto& e : s.enums)
        if (e.name == name) return Found{&s, nullptr, &e};
    return {};
}

const ServiceDefinition* find_by_name(std::span<const ServiceDefinition* const> defs, std::string_view name) {
    for (const auto* d : defs)
        if (d->name == name) return d;
    return nullptr;
}

/// Official resolution: unqualified names in `owner`, qualified names in `candidates` only.
Found resolve(std::string_view type_name, const ServiceDefinition& owner,
              std::span<const ServiceDefinition* const> candidates) {
    auto [svc, entry] = lex::split_qualified(type_name);
    if (svc.empty()) return find_in_service(owner, type_name);
    const auto* d = find_by_name(candidates, svc);
    if (!d) return {};
    return find_in_service(*d, entry);
}

std::string type_text(const TypeDefinition& t, std::string_view name) {
    std::string s = t.to_string();
    if (!name.empty()) {
        s += ' ';
        s += name;
    }
    return s;
}

class Verifier {
public:
    explicit Verifier(std::span<const ServiceDefinition* const> defs) : defs_(defs) {}
    std::vector<Diagnostic> run();

private:
    // --- reporting
    void error(int line, DiagnosticKind kind, std::string msg) {
        out_.push_back(Diagnostic{Severity::error, kind, svc_->location.file, line, std::move(msg)});
    }
    void warning(int line, DiagnosticKind kind, std::string msg) {
        out_.push_back(Diagnostic{Severity::warning, kind, svc_->location.file, line, std::move(msg)});
    }
    int line_or_service(int line) const { return line > 0 ? line : svc_->location.line; }

    // --- rules
    bool verify_name(std::string_view name, int line, bool allow_dot = false);
    bool require_version_0_9(int line, const char* msg);
    void verify_service(const ServiceDefinition& d);
    void verify_imports(const ServiceDefinition& d);
    bool imports_cycle(const ServiceDefinition& d, std::vector<const ServiceDefinition*>& path,
                       std::set<const ServiceDefinition*>& done, std::string& a, std::string& b);
    void add_high_level_name(std::set<std::string>& names, const std::string& n, int line);
    std::optional<std::string> verify_option_constant(const std::string& option, int line);
    std::optional<std::string> verify_constant(const ConstantDefinition& c,
                                               const std::vector<ConstantDefinition>& scope);
    bool verify_struct_constant(const ConstantDefinition& c, const std::vector<ConstantDefinition>& scope,
                                std::vector<std::string>& parents, const ConstantDefinition& root);
    void verify_using(const UsingDefinition& u);
    void verify_enum(const EnumDefinition& e);
    void verify_structure(const ServiceEntryDefinition& e);
    void verify_object(const ServiceEntryDefinition& e);
    bool verify_member(const MemberDefinition& m, const ServiceEntryDefinition& e);
    bool verify_type(const TypeDefinition& t, std::string_view name, int line);
    bool verify_return_type(const TypeDefinition& t, int line);
    bool verify_parameters(const std::vector<TypeDefinition>& params, int line);
    void verify_modifiers(const MemberDefinition& m, const ServiceEntryDefinition& e, bool readwrite,
                          bool unreliable, bool nolock, bool nolockread, bool perclient, bool urgent);
    void verify_unknown_modifier(const std::string& s, const MemberDefinition& m, const ServiceEntryDefinition& e);
    bool pod_recursion(const ServiceEntryDefinition& e, const ServiceDefinition& owner,
                       std::vector<std::string>& path, std::string& culprit);
    bool namedarray_elements(const ServiceEntryDefinition& e, const ServiceDefinition& owner,
                             std::vector<std::string>& path, DataTypes& type, std::string& msg);
    void verify_implements(const ServiceEntryDefinition& obj);
    bool members_match(const MemberDefinition& m1, const ServiceDefinition& d1, const MemberDefinition& m2,
                       const ServiceDefinition& d2) const;

    std::span<const ServiceDefinition* const> defs_;
    std::vector<Diagnostic> out_;
    const ServiceDefinition* svc_ = nullptr;
    std::vector<const ServiceDefinition*> imported_;
    std::set<std::string> pods_acyclic_;
    std::set<const ConstantDefinition*> struct_constants_ok_;  // verified without cycles
    std::map<std::string, DataTypes> namedarray_types_;
};

std::vector<Diagnostic> Verifier::run() {
    std::set<std::string> seen;
    for (const auto* d : defs_) {
        svc_ = d;
        if (!d->name.empty() && !seen.insert(d->name).second)
            error(d->location.line, DiagnosticKind::import,
                  "Service definition " + quoted(d->name) + " is defined more than once");
    }
    for (const auto* d : defs_) {
        svc_ = d;
        verify_service(*d);
    }
    return std::move(out_);
}

bool Verifier::verify_name(std::string_view name, int line, bool allow_dot) {
    if (name.empty()) {
        error(line, DiagnosticKind::name, "name must not be empty");
        return false;
    }
    if (name == "this" || name == "self" || name == "Me") {
        error(line, DiagnosticKind::name, "The names \"this\", \"self\", and \"Me\" are reserved");
        return false;
    }
    if (std::find(kReservedNames.begin(), kReservedNames.end(), name) != kReservedNames.end()) {
        error(line, DiagnosticKind::name, "Name " + quoted(name) + " is reserved");
        return false;
    }
    if (starts_with_ci(name, "get_") || starts_with_ci(name, "set_") || starts_with_ci(name, "rr") ||
        starts_with_ci(name, "robotraconteur") || starts_with_ci(name, "async_")) {
        error(line, DiagnosticKind::name, "Name " + quoted(name) + " is reserved or invalid");
        return false;
    }
    if (allow_dot ? !lex::is_dotted_name(name) : !lex::is_name(name)) {
        error(line, DiagnosticKind::name, "Name " + quoted(name) + " is invalid");
        return false;
    }
    return true;
}

bool Verifier::require_version_0_9(int line, const char* msg) {
    if (svc_->stdver && *svc_->stdver != Version{} && *svc_->stdver < kVersion0_9) {
        error(line, DiagnosticKind::version, msg);
        return false;
    }
    return true;
}

void Verifier::add_high_level_name(std::set<std::string>& names, const std::string& n, int line) {
    if (!names.insert(n).second)
        error(line, DiagnosticKind::duplicate,
              "Service definition " + quoted(svc_->name) + " contains multiple high level names " + quoted(n));
}

bool Verifier::imports_cycle(const ServiceDefinition& d, std::vector<const ServiceDefinition*>& path,
                             std::set<const ServiceDefinition*>& done, std::string& a, std::string& b) {
    if (done.count(&d)) return false;
    path.push_back(&d);
    for (const auto& imp : d.imports) {
        const auto* d2 = find_by_name(defs_, imp);
        if (!d2) continue;
        if (std::find(path.begin(), path.end(), d2) != path.end()) {
            a = d.name;
            b = d2->name;
            return true;
        }
        if (imports_cycle(*d2, path, done, a, b)) return true;
    }
    path.pop_back();
    done.insert(&d);
    return false;
}

void Verifier::verify_imports(const ServiceDefinition& d) {
    for (std::size_t i = 0; i < d.imports.size(); ++i) {
        int line = line_or_service(i < d.import_lines.size() ? d.import_lines[i] : 0);
        if (!find_by_name(defs_, d.imports[i]))
            error(line, DiagnosticKind::import, "Service definition " + quoted(d.imports[i]) + " not found");
    }
    std::vector<const ServiceDefinition*> path;
    std::set<const ServiceDefinition*> done;
    std::string a, b;
    if (imports_cycle(d, path, done, a, b))
        error(d.location.line, DiagnosticKind::import,
              "Recursive imports between " + quoted(a) + " and " + quoted(b));
}

std::optional<std::string> Verifier::verify_option_constant(const std::string& option, int line) {
    // Legacy `option constant …`: parsed here as a constant statement (robdef.md §7).
    auto r = parse_service_definition_report("service x\n" + option + "\n", {});
    const ConstantDefinition* c = nullptr;
    if (r.ok() && r.definition->constants.size() == 1) c = &r.definition->constants[0];
    if (!c) {
        error(line, DiagnosticKind::constant, "could not parse constant " + quoted(option));
        return std::nullopt;
    }
    if (!is_valid_constant_value(c->type, c->value) || c->type.base == DataTypes::namedtype_t) {
        error(line, DiagnosticKind::constant, "Error in constant " + c->name);
        return std::nullopt;
    }
    if (!verify_name(c->name, line)) return std::nullopt;
    return c->name;
}

bool Verifier::verify_struct_constant(const ConstantDefinition& c, const std::vector<ConstantDefinition>& scope,
                                      std::vector<std::string>& parents, const ConstantDefinition& root) {
    if (struct_constants_ok_.count(&c)) return true;
    auto fields = parse_struct_constant_fields(c.value);
    int line = root.location.line;
    if (!fields) {
        error(line, DiagnosticKind::constant, "Error in constant " + root.name);
        return false;
    }
    if (parents.size() > 64) {
        error(line, DiagnosticKind::constant, "Error in constant " + c.name + ": recursive struct not allowed");
        return false;
    }
    parents.push_back(c.name);
    for (const auto& f : *fields) {
        if (!verify_name(f.name, line)) return false;
        if (std::find(parents.begin(), parents.end(), f.constant_name) != parents.end()) {
            error(line, DiagnosticKind::constant, "Error in constant " + c.name + ": recursive struct not allowed");
            return false;
        }
        const ConstantDefinition* ref = nullptr;
        for (const auto& s : scope)
            if (s.name == f.constant_name) {
                ref = &s;
                break;
            }
        if (!ref) {
            error(line, DiagnosticKind::constant,
                  "Error in constant " + c.name + ": struct field " + f.constant_name + " not found");
            return false;
        }
        if (ref->type.base == DataTypes::namedtype_t && !verify_struct_constant(*ref, scope, parents, root))
            return false;
    }
    parents.pop_back();
    struct_constants_ok_.insert(&c);
    return true;
}

std::optional<std::string> Verifier::verify_constant(const ConstantDefinition& c,
                                                     const std::vector<ConstantDefinition>& scope) {
    int line = line_or_service(c.location.line);
    if (!is_valid_constant_value(c.type, c.value)) {
        error(line, DiagnosticKind::constant, "Error in constant " + c.name);
        return std::nullopt;
    }
    if (!verify_name(c.name, line)) return std::nullopt;
    if (c.type.base == DataTypes::namedtype_t) {
        std::vector<std::string> parents;
        if (!verify_struct_constant(c, scope, parents, c)) return std::nullopt;
    }
    return c.name;
}

void Verifier::verify_using(const UsingDefinition& u) {
    int line = line_or_service(u.location.line);
    if (!verify_name(u.unqualified_name, line)) return;
    auto invalid = [&] { error(line, DiagnosticKind::using_alias, "Using " + quoted(u.qualified_name) + " is invalid"); };
    if (!lex::is_qualified_name(u.qualified_name)) return invalid();
    auto [svc, entry] = lex::split_qualified(u.qualified_name);
    for (const auto* d : imported_) {
        if (d->name != svc) continue;
        if (find_in_service(*d, entry)) return;
        for (const auto& c : d->constants)
            if (c.name == entry) return;
        for (const auto& x : d->exceptions)
            if (x.name == entry) return;
        return invalid();
    }
    invalid();
}

void Verifier::verify_enum(const EnumDefinition& e) {
    int line = line_or_service(e.location.line);
    std::set<std::string> value_names;
    std::set<std::int32_t> values;
    for (const auto& v : e.values) {
        if (!value_names.insert(v.name).second || !values.insert(v.value).second) {
            error(v.line > 0 ? v.line : line, DiagnosticKind::enumeration, "Invalid constant in enum " + e.name);
            return;
        }
    }
    if (!verify_name(e.name, line)) return;
    for (const auto& v : e.values)
        if (!verify_name(v.name, v.line > 0 ? v.line : line)) return;
}

bool Verifier::verify_type(const TypeDefinition& t, std::string_view name, int line) {
    auto invalid = [&] {
        error(line, DiagnosticKind::type, "Invalid Robot Raconteur data type " + quoted(type_text(t, name)));
        return false;
    };
    if (t.container == ContainerKind::generator) return invalid();
    if (is_numeric(t.base)) return true;
    switch (t.base) {
        case DataTypes::string_t: return t.array == ArrayKind::none ? true : invalid();
        case DataTypes::object_t:
        case DataTypes::varvalue_t:
        case DataTypes::varobject_t: return true;  // official quirks: accepted in every form (robdef.md §6.3)
        case DataTypes::namedtype_t: {
            Found f = resolve(t.type_name, *svc_, imported_);
            if (!f) {
                error(line, DiagnosticKind::type, "could not resolve named type " + quoted(t.type_name));
                return false;
            }
            DataTypes c = f.code();
            if (c != DataTypes::pod_t && c != DataTypes::namedarray_t && t.array != ArrayKind::none) return invalid();
            if (c == DataTypes::object_t) return invalid();
            return true;
        }
        default: return invalid();
    }
}

bool Verifier::verify_return_type(const TypeDefinition& t, int line) {
    if (t.base == DataTypes::void_t) {
        if (t.array != ArrayKind::none || t.container != ContainerKind::none) {
            error(line, DiagnosticKind::type, "Invalid Robot Raconteur data type " + quoted(type_text(t, "")));
            return false;
        }
        return true;
    }
    return verify_type(t, "", line);
}

bool Verifier::verify_parameters(const std::vector<TypeDefinition>& params, int line) {
    bool ok = true;
    for (std::size_t i = 0; i < params.size(); ++i) {
        if (!verify_type(params[i], params[i].name, line)) ok = false;
        for (std::size_t j = 0; j < i; ++j)
            if (params[j].name == params[i].name) {
                error(line, DiagnosticKind::member, "Parameters must have unique names");
                return false;
            }
    }
    return ok;
}

void Verifier::verify_unknown_modifier(const std::string& s, const MemberDefinition& m,
                                       const ServiceEntryDefinition& e) {
    int line = m.location.line;
    // NAME or NAME(arg, …) with number or NAME arguments (robdef.md §5.1).
    std::string_view v = lex::trim(s);
    std::size_t k = 0;
    while (k < v.size() && lex::is_word(v[k])) ++k;
    bool ok = lex::is_name(v.substr(0, k));
    std::vector<std::string_view> args;
    if (ok && k < v.size()) {
        ok = v[k] == '(' && v.back() == ')';
        if (ok) {
            for (auto a : lex::split(v.substr(k + 1, v.size() - k - 2), ',')) {
                a = lex::trim(a);
                if (!lex::is_number_literal(a) && !lex::is_name(a)) ok = false;
                args.push_back(a);
            }
        }
    }
    if (!ok) {
        error(line, DiagnosticKind::modifier, "Invalid modifier: [" + s + "]");
        return;
    }
    for (auto a : args) {
        if (!lex::is_name(a)) continue;
        bool found = false;
        for (const auto& c : e.constants) found = found || c.name == a;
        if (!found) warning(line, DiagnosticKind::modifier, "Could not verify modifier parameters: [" + s + "]");
    }
    warning(line, DiagnosticKind::modifier, "Unknown member modifier: [" + s + "]");
}

void Verifier::verify_modifiers(const MemberDefinition& m, const ServiceEntryDefinition& e, bool readwrite,
                                bool unreliable, bool nolock, bool nolockread, bool perclient, bool urgent) {
    bool direction_found = false, unreliable_found = false, nolock_found = false, perclient_found = false,
         urgent_found = false;
    int line = m.location.line;
    auto combo = [&](const char* what) {
        warning(line, DiagnosticKind::modifier, std::string("Invalid member modifier combination: [") + what + "]");
    };
    for (const auto& s : m.modifiers) {
        if (readwrite && (s == "readonly" || s == "writeonly")) {
            if (direction_found) combo("readonly,writeonly");
            direction_found = true;
            continue;
        }
        if (unreliable && s == "unreliable") {
            MemberDefinition probe;
            probe.kind = MemberKind::pipe;
            probe.name = m.name;
            if (pipe_is_unreliable(e, probe)) combo("unreliable");
            if (unreliable_found) combo("unreliable");
            unreliable_found = true;
            continue;
        }
        if (nolock && s == "nolock") {
            if (nolock_found) combo("nolock");
            nolock_found = true;
            continue;
        }
        if (nolockread && s == "nolockread") {
            if (nolock_found) combo("nolock,nolockread");
            nolock_found = true;
            continue;
        }
        if (perclient && s == "perclient") {
            if (perclient_found) combo("perclient");
            perclient_found = true;
            continue;
        }
        if (urgent && s == "urgent") {
            if (urgent_found) combo("urgent");
            urgent_found = true;
            continue;
        }
        verify_unknown_modifier(s, m, e);
    }
}

bool Verifier::verify_member(const MemberDefinition& m, const ServiceEntryDefinition& e) {
    const int line = line_or_service(m.location.line);
    if (!verify_name(m.name, line)) return false;
    if (!m.modifiers.empty() &&
        !require_version_0_9(line, "Service definition standard version 0.9 or greater required for Member Modifiers"))
        return false;
    switch (m.kind) {
        case MemberKind::field:
        case MemberKind::property: {
            bool ok = verify_type(m.type, "value", line);
            verify_modifiers(m, e, true, false, true, true, true, true);
            return ok;
        }
        case MemberKind::function: {
            verify_modifiers(m, e, false, false, true, false, false, true);
            if (!m.is_generator())
                return verify_parameters(m.parameters, line) && verify_return_type(m.type, line);
            if (m.type.container == ContainerKind::generator) {
                if (m.type.base == DataTypes::void_t) {
                    error(line, DiagnosticKind::member, "Generator return must not be void");
                    return false;
                }
                TypeDefinition ret = m.type;
                ret.container = ContainerKind::none;
                if (!verify_type(ret, "", line)) return false;
            } else if (m.type.base != DataTypes::void_t || m.type.array != ArrayKind::none ||
                       m.type.container != ContainerKind::none) {
                error(line, DiagnosticKind::member, "Generator return must use generator container");
                return false;
            }
            if (!m.parameters.empty() && m.parameters.back().container == ContainerKind::generator) {
                TypeDefinition p = m.parameters.back();
                p.container = ContainerKind::none;
                if (!verify_type(p, p.name, line)) return false;
                std::vector<TypeDefinition> rest(m.parameters.begin(), m.parameters.end() - 1);
                return verify_parameters(rest, line);
            }
            return verify_parameters(m.parameters, line);
        }
        case MemberKind::event: {
            bool ok = verify_parameters(m.parameters, line);
            verify_modifiers(m, e, false, false, false, false, false, true);
            return ok;
        }
        case MemberKind::objref: {
            verify_modifiers(m, e, false, false, false, false, false, false);
            if (m.type.base == DataTypes::varobject_t) return true;
            const std::string& ot = m.type.type_name;
            Found f = resolve(ot, *svc_, imported_);
            if (f && f.entry && f.entry->kind == EntryKind::object) return true;
            error(line, DiagnosticKind::member, "Unknown object type " + quoted(ot));
            return false;
        }
        case MemberKind::pipe: {
            bool ok = verify_type(m.type, "value", line);
            verify_modifiers(m, e, true, true, true, false, false, false);
            return ok;
        }
        case MemberKind::callback: {
            bool ok = verify_parameters(m.parameters, line) && verify_return_type(m.type, line);
            verify_modifiers(m, e, false, false, false, false, false, true);
            return ok;
        }
        case MemberKind::wire: {
            bool ok = verify_type(m.type, "value", line);
            verify_modifiers(m, e, true, false, true, false, false, false);
            return ok;
        }
        case MemberKind::memory: {
            if (!verify_type(m.type, "value", line)) return false;
            verify_modifiers(m, e, true, false, true, true, false, false);
            if (!is_numeric(m.type.base)) {
                Found f;
                if (m.type.base == DataTypes::namedtype_t) f = resolve(m.type.type_name, *svc_, imported_);
                if (!f || (f.code() != DataTypes::pod_t && f.code() != DataTypes::namedarray_t)) {
                    error(line, DiagnosticKind::member, "Memory member must be numeric, pod, or namedarray");
                    return false;
                }
            }
            if (m.type.array == ArrayKind::none) {
                error(line, DiagnosticKind::member, "Memory member must be array or multidimarray");
                return false;
            }
            if (!m.type.array_var_length || !m.type.array_length.empty()) {
                error(line, DiagnosticKind::member, "Memory member must not be fixed size");
                return false;
            }
            return true;
        }
    }
    return false;
}

bool Verifier::pod_recursion(const ServiceEntryDefinition& e, const ServiceDefinition& owner,
                             std::vector<std::string>& path, std::string& culprit) {
    std::string q = owner.name + "." + e.name;
    if (pods_acyclic_.count(q)) return true;
    path.push_back(q);
    for (const auto& m : e.members) {
        if (m.type.base != DataTypes::namedtype_t) continue;
        Found f = resolve(m.type.type_name, owner, defs_);
        if (!f || !f.entry) continue;  // reported by the type check
        if (f.entry->kind != EntryKind::pod && f.entry->kind != EntryKind::namedarray) continue;
        if (std::find(path.begin(), path.end(), f.qualified()) != path.end()) {
            culprit = e.name;
            return false;
        }
        if (!pod_recursion(*f.entry, *f.service, path, culprit)) return false;
    }
    path.pop_back();
    pods_acyclic_.insert(q);
    return true;
}

bool Verifier::namedarray_elements(const ServiceEntryDefinition& e, const ServiceDefinition& owner,
                                   std::vector<std::string>& path, DataTypes& type, std::string& msg) {
    std::string q = owner.name + "." + e.name;
    if (auto it = namedarray_types_.find(q); it != namedarray_types_.end()) {
        type = it->second;
        return true;
    }
    if (e.members.empty()) {
        msg = "namedarray must not be empty";
        return false;
    }
    path.push_back(q);
    DataTypes element = DataTypes::void_t;
    for (const auto& m : e.members) {
        const auto& t = m.type;
        if (t.container != ContainerKind::none) {
            msg = "namedarray must not contain containers: " + e.name;
            return false;
        }
        if (t.array != ArrayKind::none && t.array_var_length) {
            msg = "namedarray must not contain variable length arrays: " + e.name;
            return false;
        }
        DataTypes field_type = DataTypes::void_t;
        if (is_numeric(t.base)) {
            field_type = t.base;
        } else if (t.base == DataTypes::namedtype_t) {
            Found f = resolve(t.type_name, owner, defs_);
            if (!f || !f.entry || f.entry->kind != EntryKind::namedarray) {
                msg = "Invalid namedarray field in " + e.name;
                return false;
            }
            if (std::find(path.begin(), path.end(), f.qualified()) != path.end()) {
                msg = "Recursive namedarray detected in " + e.name;
                return false;
            }
            if (!namedarray_elements(*f.entry, *f.service, path, field_type, msg)) return false;
        } else {
            msg = "Invalid namedarray field in " + e.name;
            return false;
        }
        if (element == DataTypes::void_t)
            element = field_type;
        else if (element != field_type) {
            msg = "namedarray must contain same numeric type: " + e.name;
            return false;
        }
    }
    path.pop_back();
    namedarray_types_[q] = element;
    type = element;
    return true;
}

void Verifier::verify_structure(const ServiceEntryDefinition& e) {
    const int line = line_or_service(e.location.line);
    if (!verify_name(e.name, line)) return;
    const bool is_pod = e.kind == EntryKind::pod;
    const bool is_na = e.kind == EntryKind::namedarray;
    std::set<std::string> names;
    auto dup = [&](const std::string& n, int at, const char* what) {
        if (!names.insert(n).second)
            error(at, DiagnosticKind::duplicate,
                  std::string(what) + " " + quoted(e.name) + " contains multiple members named " + quoted(n));
    };
    for (const auto& o : e.options) {
        if (lex::trim(o).substr(0, 8) != "constant" || (o.size() > 8 && !lex::is_blank(o[8]))) continue;
        if (auto n = verify_option_constant(o, line)) dup(*n, line, "Structure");
    }
    for (const auto& c : e.constants)
        if (auto n = verify_constant(c, e.constants)) dup(*n, line_or_service(c.location.line), "Struct");
    bool fields_ok = true;
    for (const auto& m : e.members) {
        const int mline = line_or_service(m.location.line);
        if (m.kind != MemberKind::field && m.kind != MemberKind::property) {
            error(mline, DiagnosticKind::syntax, "Structure " + quoted(e.name) + " must only contain fields");
            fields_ok = false;
            continue;
        }
        bool ok = verify_member(m, e);
        const auto& t = m.type;
        if (ok && is_pod) {
            DiagnosticKind k = DiagnosticKind::pod;
            if (!is_numeric(t.base) && t.base != DataTypes::namedtype_t) {
                error(mline, k, "Pods must only contain numeric, pod, and namedarray types");
                ok = false;
            } else if (t.base == DataTypes::namedtype_t) {
                Found f = resolve(t.type_name, *svc_, imported_);
                if (f && f.code() != DataTypes::pod_t && f.code() != DataTypes::namedarray_t) {
                    error(mline, k, "Pods must only contain numeric, namedarray, pod types");
                    ok = false;
                }
            }
            if (ok && t.container != ContainerKind::none) {
                error(mline, k, "Pods must not use containers");
                ok = false;
            }
            if (ok && t.array != ArrayKind::none &&
                (t.array_length.empty() ||
                 std::find(t.array_length.begin(), t.array_length.end(), 0) != t.array_length.end())) {
                error(mline, k, "Pods must have fixed or finite length arrays");
                ok = false;
            }
        }
        if (ok && is_na) {
            DiagnosticKind k = DiagnosticKind::namedarray;
            if (!is_numeric(t.base) && t.base != DataTypes::namedtype_t) {
                error(mline, k, "NamedArrays must only contain numeric and namedarray types: " + m.name);
                ok = false;
            } else if (t.base == DataTypes::namedtype_t) {
                Found f = resolve(t.type_name, *svc_, imported_);
                if (f && f.code() != DataTypes::namedarray_t) {
                    error(mline, k, "NamedArrays must only contain numeric and namedarray types: " + m.name);
                    ok = false;
                }
            }
            if (ok && t.container != ContainerKind::none) {
                error(mline, k, "NamedArrays may not use containers: " + m.name);
                ok = false;
            }
            if (ok && t.array != ArrayKind::none && (t.array == ArrayKind::multidimarray || t.array_var_length)) {
                error(mline, k, "NamedArray fields must be scalars or fixed arrays");
                ok = false;
            }
        }
        if (!ok) fields_ok = false;
        dup(m.name, mline, "Structure");
    }
    if (!fields_ok) return;
    if (is_pod) {
        std::vector<std::string> path;
        std::string culprit;
        if (!pod_recursion(e, *svc_, path, culprit))
            error(line, DiagnosticKind::pod, "Recursive namedarray/pod detected in " + quoted(culprit));
    }
    if (is_na) {
        std::vector<std::string> path;
        DataTypes type = DataTypes::void_t;
        std::string msg;
        if (!namedarray_elements(e, *svc_, path, type, msg))
            error(line, DiagnosticKind::namedarray, "Invalid namedarray " + quoted(e.name) + " " + msg);
    }
}

bool types_match(const TypeDefinition& t1, const ServiceDefinition& d1, const TypeDefinition& t2,
                 const ServiceDefinition& d2) {
    if (t1.name != t2.name || t1.array != t2.array || t1.container != t2.container || t1.base != t2.base)
        return false;
    if (t1.array != ArrayKind::none &&
        (t1.array_var_length != t2.array_var_length || t1.array_length != t2.array_length))
        return false;
    if (t1.base != DataTypes::namedtype_t) return true;
    auto qualify = [](const TypeDefinition& t, const ServiceDefinition& d) {
        return t.type_name.find('.') == std::string::npos ? d.name + "." + t.type_name : t.type_name;
    };
    return qualify(t1, d1) == qualify(t2, d2);
}

bool Verifier::members_match(const MemberDefinition& m1, const ServiceDefinition& d1, const MemberDefinition& m2,
                             const ServiceDefinition& d2) const {
    if (m1.name != m2.name || m1.modifiers != m2.modifiers) return false;
    auto property_like = [](MemberKind k) { return k == MemberKind::property || k == MemberKind::field; };
    if (m1.kind != m2.kind && !(property_like(m1.kind) && property_like(m2.kind))) return false;
    auto params_match = [&] {
        if (m1.parameters.size() != m2.parameters.size()) return false;
        for (std::size_t i = 0; i < m1.parameters.size(); ++i)
            if (!types_match(m1.parameters[i], d1, m2.parameters[i], d2)) return false;
        return true;
    };
    switch (m1.kind) {
        case MemberKind::function:
        case MemberKind::callback: return types_match(m1.type, d1, m2.type, d2) && params_match();
        case MemberKind::event: return params_match();
        default: return types_match(m1.type, d1, m2.type, d2);
    }
}

struct ImplementsNode {
    std::string name;  // qualified
    const ServiceDefinition* service = nullptr;
    const ServiceEntryDefinition* object = nullptr;
};

void Verifier::verify_implements(const ServiceEntryDefinition& obj) {
    const std::string root = svc_->name + "." + obj.name;
    const int obj_line = line_or_service(obj.location.line);
    // Resolves one implements name written in `owner` (qualified names among `candidates`).
    auto resolve_object = [&](const std::string& name, const ServiceDefinition& owner,
                              std::span<const ServiceDefinition* const> candidates, const std::string& in,
                              int line, bool report) -> std::optional<ImplementsNode> {
        auto [svc, entry] = lex::split_qualified(name);
        const ServiceDefinition* d = &owner;
        if (!svc.empty()) {
            d = find_by_name(candidates, svc);
            if (!d) {
                if (report)
                    error(line, DiagnosticKind::implements,
                          "Service definition " + quoted(svc) + " not found to implement in " + in);
                return std::nullopt;
            }
        }
        for (const auto& o : d->objects)
            if (o.name == entry) return ImplementsNode{d->name + "." + o.name, d, &o};
        if (report) {
            if (svc.empty())
                error(line, DiagnosticKind::implements,
                      "Object \"" + owner.name + "." + name + " not found to implement in " + in);
            else
                error(line, DiagnosticKind::implements, "Object " + quoted(name) + " not found to implement");
        }
        return std::nullopt;
    };
    auto imports_of = [&](const ServiceDefinition& d) {
        std::vector<const ServiceDefinition*> v;
        for (const auto& i : d.imports)
            if (const auto* x = find_by_name(defs_, i)) v.push_back(x);
        return v;
    };

    std::vector<ImplementsNode> direct;
    for (std::size_t i = 0; i < obj.implements.size(); ++i) {
        int line = line_or_service(i < obj.implements_lines.size() ? obj.implements_lines[i] : 0);
        auto n = resolve_object(obj.implements[i], *svc_, imported_, root, line, true);
        if (!n) return;
        if (n->name == root) {
            error(line, DiagnosticKind::implements,
                  "Recursive implements between " + quoted(root) + " and " + quoted(n->name));
            return;
        }
        direct.push_back(*n);
    }
    // Cycles through the implements graph that come back to this object.
    {
        std::set<std::string> visited;
        std::vector<ImplementsNode> stack = direct;
        while (!stack.empty()) {
            ImplementsNode n = stack.back();
            stack.pop_back();
            if (!visited.insert(n.name).second) continue;
            auto cands = imports_of(*n.service);
            for (const auto& imp : n.object->implements) {
                auto c = resolve_object(imp, *n.service, cands, n.name, 0, false);
                if (!c) continue;
                if (c->name == root) {
                    error(obj_line, DiagnosticKind::implements,
                          "Recursive implements between " + quoted(root) + " and " + quoted(c->name));
                    return;
                }
                stack.push_back(*c);
            }
        }
    }
    // No implicit inheritance: everything a direct base implements must be listed here too.
    for (const auto& n : direct) {
        auto cands = imports_of(*n.service);
        for (const auto& imp : n.object->implements) {
            auto c = resolve_object(imp, *n.service, cands, n.name, 0, false);
            if (!c) continue;
            bool listed = false;
            for (const auto& d : direct) listed = listed || d.name == c->name;
            if (!listed) {
                error(obj_line, DiagnosticKind::implements,
                      "Object " + quoted(root) + " does not implement inherited type " + quoted(c->name));
                return;
            }
        }
    }
    for (const auto& n : direct) {
        for (const auto& req : n.object->members) {
            const MemberDefinition* mine = obj.find_member(req.name);
            if (!mine) {
                error(obj_line, DiagnosticKind::implements,
                      "Object " + quoted(obj.name) + " does not implement required member " + quoted(req.name));
                continue;
            }
            if (!members_match(*mine, *svc_, req, *n.service))
                error(line_or_service(mine->location.line), DiagnosticKind::implements,
                      "Member " + quoted(req.name) + " in object " + quoted(obj.name) +
                          " does not match implemented member");
        }
    }
}

void Verifier::verify_object(const ServiceEntryDefinition& e) {
    const int line = line_or_service(e.location.line);
    if (!verify_name(e.name, line)) return;
    std::set<std::string> names;
    auto dup = [&](const std::string& n, int at) {
        if (!names.insert(n).second)
            error(at, DiagnosticKind::duplicate,
                  "Object " + quoted(e.name) + " contains multiple members named " + quoted(n));
    };
    for (const auto& o : e.options) {
        if (lex::trim(o).substr(0, 8) != "constant" || (o.size() > 8 && !lex::is_blank(o[8]))) continue;
        if (auto n = verify_option_constant(o, line)) dup(*n, line);
    }
    if (!e.constants.empty())
        require_version_0_9(line_or_service(e.constants.front().location.line),
                            "Service definition standard version 0.9 or greater required for \"constant\" keyword");
    for (const auto& c : e.constants)
        if (auto n = verify_constant(c, e.constants)) dup(*n, line_or_service(c.location.line));
    bool members_ok = true;
    for (const auto& m : e.members) {
        if (!verify_member(m, e)) members_ok = false;
        dup(m.name, line_or_service(m.location.line));
    }
    if (members_ok) verify_implements(e);
}

void Verifier::verify_service(const ServiceDefinition& d) {
    const int line = d.location.line;
    if (d.stdver && *d.stdver > kLibraryVersion)
        error(line_or_service(d.version_line), DiagnosticKind::version,
              "Service " + d.name + " requires newer version of Robot Raconteur");
    if (!(d.name.rfind("RobotRaconteurTestService", 0) == 0) && d.name != "RobotRaconteurServiceIndex")
        verify_name(d.name, line, true);
    if (d.name.size() >= 7 && d.name.compare(d.name.size() - 7, 7, "_signed") == 0)
        error(line, DiagnosticKind::name, "Service definition names ending with \"_signed\" are reserved");

    verify_imports(d);

    std::set<std::string> names;
    for (std::size_t i = 0; i < d.options.size(); ++i) {
        const auto& o = d.options[i];
        if (lex::trim(o).substr(0, 8) != "constant" || (o.size() > 8 && !lex::is_blank(o[8]))) continue;
        int oline = line_or_service(i < d.option_lines.size() ? d.option_lines[i] : 0);
        if (auto n = verify_option_constant(o, oline)) add_high_level_name(names, *n, oline);
    }
    if (!d.constants.empty())
        require_version_0_9(line_or_service(d.constants.front().location.line),
                            "Service definition standard version 0.9 or greater required for \"constant\" keyword");
    for (const auto& c : d.constants)
        if (auto n = verify_constant(c, d.constants)) add_high_level_name(names, *n, line_or_service(c.location.line));
    for (const auto& x : d.exceptions) {
        int xline = line_or_service(x.location.line);
        if (verify_name(x.name, xline)) add_high_level_name(names, x.name, xline);
    }

    imported_.clear();
    for (const auto& imp : d.imports)
        for (const auto* x : defs_)
            if (x->name == imp) imported_.push_back(x);

    if (d.stdver) {
        for (std::size_t i = 0; i < d.imports.size(); ++i) {
            const auto* x = find_by_name(defs_, d.imports[i]);
            if (!x) continue;
            if (!x->stdver || *x->stdver > *d.stdver) {
                int iline = line_or_service(i < d.import_lines.size() ? d.import_lines[i] : 0);
                error(iline, DiagnosticKind::version,
                      "Imported service definition " + x->name +
                          " has a higher Service Definition standard version than " + d.name);
            }
        }
    }

    if (!d.usings.empty())
        require_version_0_9(line_or_service(d.usings.front().location.line),
                            "Service definition standard version 0.9 or greater required for \"using\" keyword");
    for (const auto& u : d.usings) {
        add_high_level_name(names, u.unqualified_name, line_or_service(u.location.line));
        verify_using(u);
    }

    if (!d.enums.empty())
        require_version_0_9(line_or_service(d.enums.front().location.line),
                            "Service definition standard version 0.9 or greater required for \"enum\" keyword");
    for (const auto& e : d.enums) {
        verify_enum(e);
        add_high_level_name(names, e.name, line_or_service(e.location.line));
    }
    for (const auto* list : {&d.structures, &d.pods, &d.namedarrays}) {
        for (const auto& e : *list) {
            verify_structure(e);
            add_high_level_name(names, e.name, line_or_service(e.location.line));
        }
    }
    for (const auto& e : d.objects) {
        verify_object(e);
        add_high_level_name(names, e.name, line_or_service(e.location.line));
    }
}

}  // namespace

std::vector<Diagnostic> verify_service_definitions(std::span<const ServiceDefinition* const> defs) {
    Verifier v(defs);
    return v.run();
}

std::vector<Diagnostic> verify_service_definitions(std::span<const ServiceDefinition> defs) {
    std::vector<const ServiceDefinition*> ptrs;
    ptrs.reserve(defs.size());
    for (const auto& d : defs) ptrs.push_back(&d);
    return verify_service_definitions(std::span<const ServiceDefinition* const>(ptrs));
}

}  // namespace rr::robdef
