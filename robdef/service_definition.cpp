#include "robdef/service_definition.hpp"

#include <algorithm>

namespace rr::robdef {

std::string TypeDefinition::to_string() const {
    std::string s;
    if (base == DataTypes::namedtype_t)
        s = type_name;
    else
        s = std::string(data_type_keyword(base));
    if (array == ArrayKind::array) {
        s += '[';
        if (!array_length.empty() && array_length[0] != 0) {
            s += std::to_string(array_length[0]);
            if (array_var_length) s += '-';
        }
        s += ']';
    } else if (array == ArrayKind::multidimarray) {
        s += '[';
        if (array_length.empty()) {
            s += '*';
        } else {
            for (std::size_t i = 0; i < array_length.size(); ++i) {
                if (i) s += ',';
                s += std::to_string(array_length[i]);
            }
            if (array_length.size() == 1) s += ',';
        }
        s += ']';
    }
    switch (container) {
        case ContainerKind::list: s += "{list}"; break;
        case ContainerKind::map_int32: s += "{int32}"; break;
        case ContainerKind::map_string: s += "{string}"; break;
        case ContainerKind::generator: s += "{generator}"; break;
        case ContainerKind::none: break;
    }
    return s;
}

std::string_view member_kind_keyword(MemberKind kind) noexcept {
    switch (kind) {
        case MemberKind::field: return "field";
        case MemberKind::property: return "property";
        case MemberKind::function: return "function";
        case MemberKind::event: return "event";
        case MemberKind::objref: return "objref";
        case MemberKind::pipe: return "pipe";
        case MemberKind::callback: return "callback";
        case MemberKind::wire: return "wire";
        case MemberKind::memory: return "memory";
    }
    return "";
}

std::string with_article(std::string_view word) {
    const bool vowel = !word.empty() && std::string_view("aeiouAEIOU").find(word.front()) != std::string_view::npos;
    return (vowel ? "an " : "a ") + std::string(word);
}

bool MemberDefinition::has_modifier(std::string_view m) const noexcept {
    return std::find(modifiers.begin(), modifiers.end(), m) != modifiers.end();
}

MemberDirection MemberDefinition::direction() const noexcept {
    if (has_modifier("readonly")) return MemberDirection::readonly;
    if (has_modifier("writeonly")) return MemberDirection::writeonly;
    return MemberDirection::both;
}

bool MemberDefinition::is_generator() const noexcept {
    if (kind != MemberKind::function) return false;
    if (type.container == ContainerKind::generator) return true;
    return !parameters.empty() && parameters.back().container == ContainerKind::generator;
}

const MemberDefinition* ServiceEntryDefinition::find_member(std::string_view member_name) const noexcept {
    for (const auto& m : members)
        if (m.name == member_name) return &m;
    return nullptr;
}

ObjRefIndexKind objref_index_kind(const TypeDefinition& t) noexcept {
    if (t.container == ContainerKind::map_string) return ObjRefIndexKind::string;
    if (t.container == ContainerKind::map_int32 || t.array != ArrayKind::none) return ObjRefIndexKind::int32;
    return ObjRefIndexKind::none;
}

bool pipe_is_unreliable(const ServiceEntryDefinition& entry, const MemberDefinition& pipe) noexcept {
    if (pipe.kind != MemberKind::pipe) return false;
    if (pipe.has_modifier("unreliable")) return true;
    auto blank = [](char c) { return c == ' ' || c == '\t'; };
    for (const auto& o : entry.options) {
        // `pipe <name> unreliable`, blank separated.
        std::string_view s = o;
        std::string_view words[3];
        int n = 0;
        std::size_t i = 0;
        while (i < s.size() && n <= 3) {
            while (i < s.size() && blank(s[i])) ++i;
            if (i == s.size()) break;
            std::size_t k = i;
            while (k < s.size() && !blank(s[k])) ++k;
            if (n < 3) words[n] = s.substr(i, k - i);
            ++n;
            i = k;
        }
        if (n == 3 && words[0] == "pipe" && words[1] == pipe.name && words[2] == "unreliable") return true;
    }
    return false;
}

std::string Version::to_string() const {
    // Appends piecewise (GCC 12 warns falsely on `"." + std::string` at -O2, bug 105651).
    std::string s = std::to_string(major);
    s += '.';
    s += std::to_string(minor);
    if (patch || tweak) {
        s += '.';
        s += std::to_string(patch);
    }
    if (tweak) {
        s += '.';
        s += std::to_string(tweak);
    }
    return s;
}

const ServiceEntryDefinition* ServiceDefinition::find_entry(std::string_view entry_name) const noexcept {
    for (const auto* list : {&structures, &pods, &namedarrays, &objects})
        for (const auto& e : *list)
            if (e.name == entry_name) return &e;
    return nullptr;
}

const EnumDefinition* ServiceDefinition::find_enum(std::string_view enum_name) const noexcept {
    for (const auto& e : enums)
        if (e.name == enum_name) return &e;
    return nullptr;
}

const ExceptionDefinition* ServiceDefinition::find_exception(std::string_view exception_name) const noexcept {
    for (const auto& e : exceptions)
        if (e.name == exception_name) return &e;
    return nullptr;
}

}  // namespace rr::robdef
