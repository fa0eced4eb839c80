#include "robdef/canonical_text.hpp"

#include <cstdint>

namespace rr::robdef {
namespace {

// A qualified name written back as its `using` alias, when there is one.
std::string unqualify(const std::string& name, const ServiceDefinition& def) {
    if (name.find('.') == std::string::npos) return name;
    for (const auto& u : def.usings)
        if (u.qualified_name == name) return u.unqualified_name;
    return name;
}

std::string type_string(const TypeDefinition& t, const ServiceDefinition& def, std::string_view name) {
    TypeDefinition c = t;
    if (c.base == DataTypes::namedtype_t) c.type_name = unqualify(c.type_name, def);
    std::string s = c.to_string();
    if (!name.empty()) {
        s += ' ';
        s += name;
    }
    return s;
}

std::string params_string(const std::vector<TypeDefinition>& params, const ServiceDefinition& def) {
    std::string s;
    for (std::size_t i = 0; i < params.size(); ++i) {
        if (i) s += ", ";
        s += type_string(params[i], def, params[i].name);
    }
    return s;
}

std::string modifiers_string(const std::vector<std::string>& mods) {
    if (mods.empty()) return {};
    std::string s = " [";
    for (std::size_t i = 0; i < mods.size(); ++i) {
        if (i) s += ',';
        s += mods[i];
    }
    return s + "]";
}

std::string hex_string(std::uint32_t v) {
    static constexpr char kDigits[] = "0123456789abcdef";
    std::string s;
    do {
        s.insert(s.begin(), kDigits[v & 0xf]);
        v >>= 4;
    } while (v);
    return s;
}

std::string enum_to_string(const EnumDefinition& e) {
    std::string s = "enum " + e.name + "\n";
    for (std::size_t i = 0; i < e.values.size(); ++i) {
        const auto& v = e.values[i];
        s += "    " + v.name;
        if (!v.implicit) {
            if (!v.hex) {
                s += " = " + std::to_string(v.value);
            } else if (v.value >= 0) {
                s += " = 0x" + hex_string(static_cast<std::uint32_t>(v.value));
            } else {
                s += " = -0x" + hex_string(static_cast<std::uint32_t>(-static_cast<std::int64_t>(v.value)));
            }
        }
        s += i + 1 < e.values.size() ? ",\n" : "\n";
    }
    if (e.values.empty()) s += "\n";
    return s + "end\n";
}

std::string constant_to_string(const ConstantDefinition& c) {
    return "constant " + c.type.to_string() + " " + c.name + " " + c.value;
}

// An option's text is free; one ending in `\` (left by a continuation onto a blank line) would continue
// onto the next line when read back, so it gets one more `\` continued onto a blank line (robdef.md
// §1.2: that backslash becomes a space, which the parser trims).
std::string option_line(std::string_view indent, const std::string& text) {
    std::string line = std::string(indent) + "option " + text;
    return line + (!text.empty() && text.back() == '\\' ? "\\\n\n" : "\n");
}

std::string entry_to_string(const ServiceEntryDefinition& e, const ServiceDefinition& def) {
    std::string s;
    switch (e.kind) {
        case EntryKind::structure: s = "struct "; break;
        case EntryKind::pod: s = "pod "; break;
        case EntryKind::namedarray: s = "namedarray "; break;
        case EntryKind::object: s = "object "; break;
    }
    s += e.name + "\n";
    for (const auto& i : e.implements) s += "    implements " + unqualify(i, def) + "\n";
    for (const auto& o : e.options) s += option_line("    ", o);
    for (const auto& c : e.constants) s += "    " + constant_to_string(c) + "\n";
    for (const auto& m : e.members) s += "    " + member_to_string(m, def, e.kind == EntryKind::object) + "\n";
    return s + "end\n";
}

}  // namespace

std::string member_to_string(const MemberDefinition& m, const ServiceDefinition& def, bool in_object) {
    switch (m.kind) {
        case MemberKind::function:
        case MemberKind::callback:
            return std::string(member_kind_keyword(m.kind)) + " " + type_string(m.type, def, m.name) + "(" +
                   params_string(m.parameters, def) + ")" + modifiers_string(m.modifiers);
        case MemberKind::event:
            return "event " + m.name + "(" + params_string(m.parameters, def) + ")" + modifiers_string(m.modifiers);
        case MemberKind::field:
        case MemberKind::property:
            return std::string(in_object ? "property " : "field ") + type_string(m.type, def, m.name) +
                   modifiers_string(m.modifiers);
        default:
            return std::string(member_kind_keyword(m.kind)) + " " + type_string(m.type, def, m.name) +
                   modifiers_string(m.modifiers);
    }
}

std::string to_string(const ServiceDefinition& def) {
    std::string o = "service " + def.name + "\n\n";
    // Top-level options are legal above `stdver` >= 0.9.2 but not below it (robdef.md §2.2). The
    // official ToString writes them below and cannot read its own text back; ours go above then.
    const bool options_first =
        def.stdver && !def.version_from_option && *def.stdver >= Version{0, 9, 2, 0} && !def.options.empty();
    if (options_first) {
        for (const auto& opt : def.options) o += option_line("", opt);
        o += "\n";
    }
    if (def.stdver && !def.version_from_option) {
        o += (*def.stdver < Version{0, 9, 0, 0} ? "option version " : "stdver ") + def.stdver->to_string() + "\n\n";
    }
    for (const auto& i : def.imports) o += "import " + i + "\n";
    if (!def.imports.empty()) o += "\n";
    for (const auto& u : def.usings) {
        auto last = u.qualified_name.substr(u.qualified_name.rfind('.') + 1);
        o += "using " + u.qualified_name + (last == u.unqualified_name ? "" : " as " + u.unqualified_name) + "\n";
    }
    if (!def.usings.empty()) o += "\n";
    if (!options_first) {
        for (const auto& opt : def.options) o += option_line("", opt);
        if (!def.options.empty()) o += "\n";
    }
    for (const auto& c : def.constants) o += constant_to_string(c) + "\n";
    if (!def.constants.empty()) o += "\n";
    for (const auto& e : def.enums) o += enum_to_string(e) + "\n";
    if (!def.enums.empty()) o += "\n";
    for (const auto& x : def.exceptions) o += "exception " + x.name + "\n";
    if (!def.exceptions.empty()) o += "\n";
    for (const auto* list : {&def.structures, &def.pods, &def.namedarrays, &def.objects})
        for (const auto& e : *list) o += entry_to_string(e, def) + "\n";
    return o;
}

}  // namespace rr::robdef
