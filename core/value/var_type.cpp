#include "core/value/var_type.hpp"

#include <charconv>

namespace rr {

using robdef::ArrayKind;
using robdef::ContainerKind;
using robdef::TypeDefinition;

std::string var_type_string(const Value& v) {
    switch (v.kind()) {
        case ValueKind::null: return "";
        case ValueKind::numeric:
            return std::string(data_type_keyword(v.get_if<NumericArray>()->type())) + "[]";
        case ValueKind::string: return "string";
        case ValueKind::multidim:
            return std::string(data_type_keyword(v.get_if<MultiDimArray>()->array.type())) + "[*]";
        case ValueKind::structure: return v.get_if<Structure>()->type_name;
        case ValueKind::pod: {
            auto* p = v.get_if<PodArray>();
            return p->type_name + (p->dims.empty() ? "[]" : "[*]");
        }
        case ValueKind::namedarray: {
            auto* n = v.get_if<NamedArray>();
            return n->type_name + (n->dims.empty() ? "[]" : "[*]");
        }
        case ValueKind::map_int32: return "varvalue{int32}";
        case ValueKind::map_string: return "varvalue{string}";
        case ValueKind::list: return "varvalue{list}";
        case ValueKind::enumeration: {
            auto* e = v.get_if<Enum>();
            return e->type_name.empty() ? "int32" : e->type_name;
        }
    }
    return "";
}

DataTypes keyword_data_type(std::string_view word) noexcept {
    for (auto t : {DataTypes::void_t, DataTypes::double_t, DataTypes::single_t, DataTypes::int8_t,
                   DataTypes::uint8_t, DataTypes::int16_t, DataTypes::uint16_t, DataTypes::int32_t,
                   DataTypes::uint32_t, DataTypes::int64_t, DataTypes::uint64_t, DataTypes::string_t,
                   DataTypes::cdouble_t, DataTypes::csingle_t, DataTypes::bool_t, DataTypes::varvalue_t,
                   DataTypes::structure_t, DataTypes::object_t, DataTypes::varobject_t})
        if (data_type_keyword(t) == word) return t;
    return DataTypes::namedtype_t;
}

namespace {

bool is_space(char c) { return c == ' ' || c == '\t'; }
bool is_alpha(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z'); }
bool is_digit(char c) { return c >= '0' && c <= '9'; }

bool parse_dim(std::string_view s, std::int32_t& out) {
    if (s.empty()) return false;
    for (char c : s)
        if (!is_digit(c)) return false;
    std::uint32_t v = 0;
    auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (ec != std::errc() || p != s.data() + s.size() || v > 0x7fffffffu) return false;
    out = static_cast<std::int32_t>(v);
    return true;
}

bool parse_array(std::string_view a, TypeDefinition& t) {
    if (a.empty()) {
        t.array = ArrayKind::array;
        t.array_var_length = true;
        return true;
    }
    if (a == "*") {
        t.array = ArrayKind::multidimarray;
        t.array_var_length = true;
        return true;
    }
    if (a.back() == '-') {
        std::int32_t n = 0;
        if (!parse_dim(a.substr(0, a.size() - 1), n)) return false;
        t.array = ArrayKind::array;
        t.array_var_length = true;
        if (n != 0) t.array_length = {n};
        return true;
    }
    if (a.find(',') == std::string_view::npos) {
        std::int32_t n = 0;
        if (!parse_dim(a, n)) return false;
        t.array = ArrayKind::array;
        t.array_var_length = (n == 0);
        if (n != 0) t.array_length = {n};
        return true;
    }
    t.array = ArrayKind::multidimarray;
    t.array_var_length = false;
    if (a.back() == ',') {  // `[N,]`
        std::int32_t n = 0;
        if (!parse_dim(a.substr(0, a.size() - 1), n)) return false;
        t.array_length = {n};
        return true;
    }
    std::size_t start = 0;
    while (start <= a.size()) {
        std::size_t comma = a.find(',', start);
        std::string_view part = a.substr(start, comma == std::string_view::npos ? a.npos : comma - start);
        std::int32_t n = 0;
        if (!parse_dim(part, n)) return false;
        t.array_length.push_back(n);
        if (comma == std::string_view::npos) break;
        start = comma + 1;
    }
    return t.array_length.size() >= 2;
}

}  // namespace

Result<TypeDefinition> parse_type_string(std::string_view text) {
    auto bad = [&](std::string_view why) {
        return fail(MessageErrorType::DataTypeError,
                    "invalid type string \"" + std::string(text) + "\": " + std::string(why));
    };
    std::string_view s = text;
    while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
    while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
    std::size_t sp = 0;
    while (sp < s.size() && !is_space(s[sp])) ++sp;
    std::string_view token = s.substr(0, sp);
    std::string_view name = s.substr(sp);
    while (!name.empty() && is_space(name.front())) name.remove_prefix(1);
    for (char c : name)
        if (!(is_alpha(c) || is_digit(c) || c == '_')) return bad("bad name after the type");

    TypeDefinition t;
    t.name = std::string(name);
    std::size_t i = 0;
    if (token.empty() || !is_alpha(token[0])) return bad("expected a type name");
    while (i < token.size() && (is_alpha(token[i]) || is_digit(token[i]) || token[i] == '_' || token[i] == '.')) ++i;
    std::string_view base = token.substr(0, i);
    if (base.back() == '.' || base.find("..") != std::string_view::npos) return bad("bad qualified name");
    t.base = keyword_data_type(base);
    if (t.base == DataTypes::structure_t || t.base == DataTypes::object_t || t.base == DataTypes::varobject_t)
        return bad("not a value type");
    if (t.base == DataTypes::namedtype_t) t.type_name = std::string(base);

    if (i < token.size() && token[i] == '[') {
        std::size_t close = token.find(']', i);
        if (close == std::string_view::npos) return bad("unterminated [");
        if (!parse_array(token.substr(i + 1, close - i - 1), t)) return bad("bad array suffix");
        i = close + 1;
    }
    if (i < token.size() && token[i] == '{') {
        std::size_t close = token.find('}', i);
        if (close == std::string_view::npos) return bad("unterminated {");
        std::string_view c = token.substr(i + 1, close - i - 1);
        if (c == "list")
            t.container = ContainerKind::list;
        else if (c == "int32")
            t.container = ContainerKind::map_int32;
        else if (c == "string")
            t.container = ContainerKind::map_string;
        else
            return bad("container must be {list}, {int32} or {string}");
        i = close + 1;
    }
    if (i != token.size()) return bad("unexpected text after the type");
    if (t.base == DataTypes::void_t && (t.array != ArrayKind::none || t.container != ContainerKind::none))
        return bad("void cannot be an array or container");
    return t;
}

}  // namespace rr
