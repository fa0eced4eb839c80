// Hand-written parser for service definitions. The grammar and error texts follow robdef.md
// (§1–§9); every step is a small scanner over std::string_view, no regex.
#include "robdef/parser.hpp"

#include <array>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <set>

#include "robdef/lexer.hpp"

namespace rr::robdef {

FileText definition_file_text(std::string bytes, std::string_view file_name) {
    FileText out;
    if (std::string_view(bytes).substr(0, kUtf8ByteOrderMark.size()) == kUtf8ByteOrderMark) {
        bytes.erase(0, kUtf8ByteOrderMark.size());
        out.diagnostics.push_back(Diagnostic{
            Severity::warning, DiagnosticKind::syntax, std::string(file_name), 1,
            "the file starts with a UTF-8 byte-order mark (bytes EF BB BF): dropped here and by the official "
            "file readers (RobotRaconteurGen, RegisterServiceTypeFromFile), but the official parser refuses the "
            "text with it (RegisterServiceType, a definition sent by a service); save the file without it"});
    }
    out.text = std::move(bytes);
    return out;
}

using lex::is_alpha;
using lex::is_blank;
using lex::is_digit;
using lex::is_word;
using lex::trim;
using lex::trim_left;
using lex::trim_right;

namespace {

constexpr Version kVersion0_9{0, 9, 0, 0};
constexpr Version kVersion0_9_2{0, 9, 2, 0};

DataTypes data_type_from_keyword(std::string_view s, bool& named) {
    static constexpr std::array kTypes{
        DataTypes::void_t,      DataTypes::double_t,  DataTypes::single_t,    DataTypes::int8_t,
        DataTypes::uint8_t,     DataTypes::int16_t,   DataTypes::uint16_t,    DataTypes::int32_t,
        DataTypes::uint32_t,    DataTypes::int64_t,   DataTypes::uint64_t,    DataTypes::string_t,
        DataTypes::cdouble_t,   DataTypes::csingle_t, DataTypes::bool_t,      DataTypes::structure_t,
        DataTypes::object_t,    DataTypes::varvalue_t, DataTypes::varobject_t};
    for (auto t : kTypes) {
        if (data_type_keyword(t) == s) {
            named = false;
            return t;
        }
    }
    named = true;
    return DataTypes::namedtype_t;
}

// Parses decimal digits into an int32 through uint32, as the official parser does; false when the
// text is empty, not digits, or above 2^31-1.
bool parse_dimension(std::string_view s, std::int32_t& out) {
    if (s.empty()) return false;
    std::uint64_t v = 0;
    for (char c : s) {
        if (!is_digit(c)) return false;
        v = v * 10 + static_cast<std::uint64_t>(c - '0');
        if (v > static_cast<std::uint64_t>(std::numeric_limits<std::int32_t>::max())) return false;
    }
    out = static_cast<std::int32_t>(v);
    return true;
}

// The type token grammar of robdef.md §6.1 with an optional trailing name. On failure `err` holds
// the official message.
bool parse_type_token(std::string_view text, TypeDefinition& t, std::string& err) {
    std::string_view s = trim(text);
    auto bad = [&](std::string_view suffix = {}) {
        err = "Could not parse type \"" + std::string(s) + "\"" + std::string(suffix);
        return false;
    };
    t = TypeDefinition{};
    std::size_t i = 0;
    if (s.empty() || !is_alpha(s[0])) return bad();
    while (i < s.size() && (is_word(s[i]) || s[i] == '.')) ++i;
    std::string_view base = s.substr(0, i);

    if (i < s.size() && s[i] == '[') {
        auto close = s.find(']', i);
        if (close == std::string_view::npos) return bad();
        std::string_view inner = s.substr(i + 1, close - i - 1);
        i = close + 1;
        for (char c : inner)
            if (!is_digit(c) && c != ',' && c != '*' && c != '-') return bad();
        if (inner.empty()) {
            t.array = ArrayKind::array;
            t.array_var_length = true;
        } else if (inner == "*") {
            t.array = ArrayKind::multidimarray;
            t.array_var_length = true;
        } else if (inner.back() == '-') {
            std::int32_t n = 0;
            if (!parse_dimension(inner.substr(0, inner.size() - 1), n)) return bad();
            t.array = ArrayKind::array;
            t.array_var_length = true;
            if (n != 0) t.array_length = {n};
        } else if (inner.find_first_not_of("0123456789") == std::string_view::npos) {
            std::int32_t n = 0;
            if (!parse_dimension(inner, n)) return bad();
            t.array = ArrayKind::array;
            t.array_var_length = n == 0;  // `[0]` behaves as `[]` (robdef.md §6.1)
            if (n != 0) t.array_length = {n};
        } else {
            // `[N,]` or `[N,M,…]`: digits and commas only.
            if (inner.find_first_of("*-") != std::string_view::npos) return bad();
            t.array = ArrayKind::multidimarray;
            t.array_var_length = false;
            auto dims = lex::split(inner, ',');
            if (dims.size() == 2 && dims[1].empty()) dims.pop_back();  // `[N,]`
            for (auto d : dims) {
                std::int32_t n = 0;
                if (!parse_dimension(d, n)) return bad();
                t.array_length.push_back(n);
            }
        }
    }
    if (i < s.size() && s[i] == '{') {
        auto close = s.find('}', i);
        if (close == std::string_view::npos) return bad();
        std::string_view inner = s.substr(i + 1, close - i - 1);
        if (inner.empty() || inner.size() > 16 || !lex::is_word_run(inner)) return bad();
        i = close + 1;
        if (inner == "list")
            t.container = ContainerKind::list;
        else if (inner == "int32")
            t.container = ContainerKind::map_int32;
        else if (inner == "string")
            t.container = ContainerKind::map_string;
        else if (inner == "generator")
            t.container = ContainerKind::generator;
        else
            return bad(": invalid container type");
    }
    if (i < s.size()) {
        if (!is_blank(s[i])) return bad();
        auto name = trim(s.substr(i));
        if (!lex::is_word_run(name)) return bad();
        t.name = std::string(name);
    }
    bool named = false;
    t.base = data_type_from_keyword(base, named);
    if (named) t.type_name = std::string(base);
    return true;
}

// TYPE2 of a constant: dotted name, optional `[…]` of [0-9,*-], optional `{word}`.
bool is_constant_type_token(std::string_view s) {
    std::size_t i = 0;
    while (i < s.size() && (is_word(s[i]) || s[i] == '.')) ++i;
    if (!lex::is_dotted_name(s.substr(0, i))) return false;
    if (i < s.size() && s[i] == '[') {
        auto close = s.find(']', i);
        if (close == std::string_view::npos) return false;
        for (std::size_t k = i + 1; k < close; ++k)
            if (!is_digit(s[k]) && s[k] != ',' && s[k] != '*' && s[k] != '-') return false;
        i = close + 1;
    }
    if (i < s.size() && s[i] == '{') {
        auto close = s.find('}', i);
        if (close == std::string_view::npos) return false;
        auto inner = s.substr(i + 1, close - i - 1);
        if (inner.empty() || inner.size() > 16 || !lex::is_word_run(inner)) return false;
        i = close + 1;
    }
    return i == s.size();
}

// Integer literal (decimal or hex) in the range of an integer type. Unsigned types also accept a
// negative magnitude up to their maximum (it wraps, as in the official parser).
bool integer_in_range(DataTypes type, std::string_view lit) {
    bool neg = false;
    if (!lit.empty() && (lit[0] == '+' || lit[0] == '-')) {
        neg = lit[0] == '-';
        lit.remove_prefix(1);
    }
    unsigned base = 10;
    if (lit.size() > 2 && lit[0] == '0' && lit[1] == 'x') {
        base = 16;
        lit.remove_prefix(2);
    }
    std::uint64_t mag = 0;
    for (char c : lit) {
        unsigned d = is_digit(c) ? unsigned(c - '0') : unsigned((c | 0x20) - 'a' + 10);
        if (mag > (std::numeric_limits<std::uint64_t>::max() - d) / base) return false;
        mag = mag * base + d;
    }
    int bits = 0;
    bool is_signed = false;
    switch (type) {
        case DataTypes::int8_t: bits = 8; is_signed = true; break;
        case DataTypes::uint8_t: bits = 8; break;
        case DataTypes::int16_t: bits = 16; is_signed = true; break;
        case DataTypes::uint16_t: bits = 16; break;
        case DataTypes::int32_t: bits = 32; is_signed = true; break;
        case DataTypes::uint32_t: bits = 32; break;
        case DataTypes::int64_t: bits = 64; is_signed = true; break;
        case DataTypes::uint64_t: bits = 64; break;
        default: return false;
    }
    if (is_signed) {
        std::uint64_t max_pos = (std::uint64_t{1} << (bits - 1)) - 1;
        return neg ? mag <= max_pos + 1 : mag <= max_pos;
    }
    std::uint64_t max = bits == 64 ? std::numeric_limits<std::uint64_t>::max() : (std::uint64_t{1} << bits) - 1;
    return mag <= max;
}

bool float_in_range(DataTypes type, std::string_view lit) {
    std::string s(lit);
    if (type == DataTypes::single_t) {
        float v = std::strtof(s.c_str(), nullptr);
        return std::isfinite(v);
    }
    double v = std::strtod(s.c_str(), nullptr);
    return std::isfinite(v);
}

bool scalar_ok(DataTypes type, std::string_view lit) {
    lit = trim(lit);
    if (type == DataTypes::double_t || type == DataTypes::single_t)
        return lex::is_float_literal(lit) && float_in_range(type, lit);
    // The official parser converts 8-bit integers as characters: exactly one digit passes
    // (robdef.md §7). A wider value would break every official peer that parses the definition.
    if (type == DataTypes::int8_t || type == DataTypes::uint8_t) return lit.size() == 1 && is_digit(lit[0]);
    return (lex::is_int_literal(lit) || lex::is_hex_literal(lit)) && integer_in_range(type, lit);
}

bool string_constant_ok(std::string_view v) {
    v = trim(v);
    if (v.size() < 2 || v.front() != '"' || v.back() != '"') return false;
    v = v.substr(1, v.size() - 2);
    for (std::size_t i = 0; i < v.size(); ++i) {
        char c = v[i];
        if (c == '"') return false;
        if (c != '\\') continue;
        if (i + 1 >= v.size()) return false;
        char e = v[++i];
        switch (e) {
            case '"': case '\\': case '/': case 'b': case 'f': case 'n': case 'r': case 't': break;
            case 'u':
                if (i + 4 >= v.size()) return false;
                for (int k = 1; k <= 4; ++k)
                    if (!lex::is_hex_digit(v[i + k])) return false;
                i += 4;
                break;
            default: return false;
        }
    }
    return true;
}

}  // namespace

bool is_valid_constant_value(const TypeDefinition& t, std::string_view value) {
    if (t.array == ArrayKind::multidimarray) return false;
    if (is_numeric(t.base)) {
        if (t.base == DataTypes::cdouble_t || t.base == DataTypes::csingle_t || t.base == DataTypes::bool_t)
            return false;
        if (t.container != ContainerKind::none) return false;
        if (t.array == ArrayKind::none) return scalar_ok(t.base, value);
        auto v = trim(value);
        if (v.size() < 2 || v.front() != '{' || v.back() != '}') return false;
        auto inner = trim(v.substr(1, v.size() - 2));
        if (inner.empty()) return true;
        for (auto e : lex::split(inner, ','))
            if (!scalar_ok(t.base, e)) return false;
        return true;
    }
    // A container on a string or struct constant is not checked, as in the official parser.
    if (t.array != ArrayKind::none) return false;
    if (t.base == DataTypes::string_t) return string_constant_ok(value);
    if (t.base == DataTypes::namedtype_t) return parse_struct_constant_fields(value).has_value();
    return false;
}

std::optional<std::vector<StructConstantField>> parse_struct_constant_fields(std::string_view value) {
    auto v = trim(value);
    if (v.size() < 2 || v.front() != '{' || v.back() != '}') return std::nullopt;
    auto inner = trim(v.substr(1, v.size() - 2));
    std::vector<StructConstantField> out;
    if (inner.empty()) return out;
    for (auto piece : lex::split(inner, ',')) {
        auto colon = piece.find(':');
        if (colon == std::string_view::npos) return std::nullopt;
        auto name = trim(piece.substr(0, colon));
        auto ref = trim(piece.substr(colon + 1));
        if (!lex::is_name(name) || !lex::is_name(ref)) return std::nullopt;
        out.push_back({std::string(name), std::string(ref)});
    }
    return out;
}

namespace {

// ---------------------------------------------------------------------------------------------
// Member line grammar (robdef.md §4, §5.1)

struct MemberParts {
    std::string_view keyword;
    std::optional<std::string_view> type;
    std::string_view name;
    std::optional<std::vector<std::string_view>> params;
    std::optional<std::vector<std::string_view>> modifiers;
};

constexpr bool is_type_char(char c) noexcept {
    return is_word(c) || c == '{' || c == '}' || c == '[' || c == ']' || c == '*' || c == ',' || c == '-' ||
           c == '.';
}

std::size_t skip_blanks(std::string_view s, std::size_t i) {
    while (i < s.size() && is_blank(s[i])) ++i;
    return i;
}

// Parameter list: `TYPE name (, TYPE name)*` or blank.
bool parse_params(std::string_view s, std::vector<std::string_view>& out) {
    if (trim(s).empty()) return true;
    std::size_t i = 0;
    while (true) {
        i = skip_blanks(s, i);
        std::size_t start = i;
        std::size_t k = i;
        while (k < s.size() && (is_word(s[k]) || s[k] == '.')) ++k;
        if (!lex::is_dotted_name(s.substr(i, k - i))) return false;
        if (k < s.size() && s[k] == '[') {
            auto close = s.find(']', k);
            if (close == std::string_view::npos) return false;
            for (auto c = k + 1; c < close; ++c)
                if (!is_digit(s[c]) && s[c] != ',' && s[c] != '*' && s[c] != '-') return false;
            k = close + 1;
        }
        if (k < s.size() && s[k] == '{') {
            auto close = s.find('}', k);
            if (close == std::string_view::npos) return false;
            auto inner = s.substr(k + 1, close - k - 1);
            if (inner.empty() || inner.size() > 16 || !lex::is_word_run(inner)) return false;
            k = close + 1;
        }
        std::size_t n = skip_blanks(s, k);
        if (n == k) return false;
        std::size_t e = n;
        while (e < s.size() && is_word(s[e])) ++e;
        if (e == n) return false;
        out.push_back(s.substr(start, e - start));
        i = skip_blanks(s, e);
        if (i == s.size()) return true;
        if (s[i] != ',') return false;
        ++i;
        auto rest = s.substr(i);
        bool has_word = false;
        for (char c : rest) has_word = has_word || is_word(c);
        if (!has_word) return false;
    }
}

bool is_modifier_arg(std::string_view a) { return lex::is_number_literal(a) || lex::is_name(a); }

// Modifier list inside `[ … ]`: NAME or NAME(arg, …), comma separated, trailing comma allowed.
bool parse_modifiers(std::string_view s, std::vector<std::string_view>& out) {
    if (trim(s).empty()) return false;
    std::size_t i = 0;
    while (true) {
        i = skip_blanks(s, i);
        std::size_t start = i;
        std::size_t k = i;
        while (k < s.size() && is_word(s[k])) ++k;
        if (!lex::is_name(s.substr(i, k - i))) return false;
        if (k < s.size() && s[k] == '(') {
            auto close = s.find(')', k);
            if (close == std::string_view::npos) return false;
            auto args = s.substr(k + 1, close - k - 1);
            if (trim(args).empty()) return false;
            for (auto a : lex::split(args, ','))
                if (!is_modifier_arg(trim(a))) return false;
            k = close + 1;
        }
        out.push_back(s.substr(start, k - start));
        if (k == s.size()) return true;
        i = skip_blanks(s, k);  // blanks only before a comma (`[readonly ]` is rejected)
        if (i == s.size() || s[i] != ',') return false;
        ++i;
        if (trim(s.substr(i)).empty()) return true;
    }
}

bool parse_member_parts(std::string_view s, MemberParts& p) {
    std::size_t i = skip_blanks(s, 0);
    std::size_t k = i;
    while (k < s.size() && is_alpha(s[k])) ++k;
    if (k == i) return false;
    p.keyword = s.substr(i, k - i);
    i = skip_blanks(s, k);
    if (i == k) return false;
    std::size_t t_end = i;
    while (t_end < s.size() && is_type_char(s[t_end])) ++t_end;
    if (t_end == i) return false;
    std::string_view token1 = s.substr(i, t_end - i);
    std::size_t after = skip_blanks(s, t_end);
    if (after > t_end && after < s.size() && is_word(s[after]) && is_alpha(token1[0])) {
        p.type = token1;
        std::size_t n_end = after;
        while (n_end < s.size() && is_word(s[n_end])) ++n_end;
        p.name = s.substr(after, n_end - after);
        i = n_end;
    } else {
        if (!lex::is_word_run(token1)) return false;
        p.name = token1;
        i = t_end;
    }
    std::size_t j = skip_blanks(s, i);
    if (j < s.size() && s[j] == '(') {
        auto close = s.find(')', j);
        if (close == std::string_view::npos) return false;
        p.params.emplace();
        if (!parse_params(s.substr(j + 1, close - j - 1), *p.params)) return false;
        i = close + 1;
    }
    j = skip_blanks(s, i);
    if (j > i && j < s.size() && s[j] == '[') {
        auto close = s.find(']', j);
        if (close == std::string_view::npos) return false;
        p.modifiers.emplace();
        if (!parse_modifiers(s.substr(j + 1, close - j - 1), *p.modifiers)) return false;
        i = close + 1;
    }
    return skip_blanks(s, i) == s.size();
}

// ---------------------------------------------------------------------------------------------

struct ParseFailure {
    int line = 0;
    DiagnosticKind kind = DiagnosticKind::syntax;
    std::string message;
};

class Parser {
public:
    Parser(std::string_view text, std::string_view file) : reader_(text), file_(file) {
        def_.location = loc(0);
    }

    ParseReport run();

private:
    bool fail(int line, DiagnosticKind kind, std::string message) {
        if (!failure_) failure_ = ParseFailure{line, kind, std::move(message)};
        return false;
    }
    void warn(int line, DiagnosticKind kind, std::string message) {
        warnings_.push_back(Diagnostic{Severity::warning, kind, file_, line, std::move(message)});
    }
    bool reader_failed() {
        if (auto& e = reader_.error()) return fail(e->first, DiagnosticKind::syntax, e->second);
        return true;
    }
    SourceLocation loc(int line) const { return SourceLocation{file_, line}; }

    bool statement(lex::LogicalLine& ll);
    bool parse_version(std::string_view v, int line, Version& out);
    bool collect_block(const lex::LogicalLine& opener, std::string_view kind, std::string_view& name,
                       std::vector<lex::LogicalLine>& body, int& end_line);
    bool parse_enum(const lex::LogicalLine& opener);
    bool parse_entry(const lex::LogicalLine& opener, EntryKind kind, std::string_view kw);
    bool parse_constant(const lex::LogicalLine& ll, ConstantDefinition& c);
    bool parse_member(const lex::LogicalLine& ll, std::string_view kw, ServiceEntryDefinition& e);
    bool parse_member_type(std::string_view text, int line, TypeDefinition& t);
    void qualify(std::string& type_name) const;
    bool finish_versions();

    lex::LineReader reader_;
    std::string file_;
    ServiceDefinition def_;
    std::vector<Diagnostic> warnings_;
    std::optional<ParseFailure> failure_;
    Version stdver_{};  // version from `stdver` lines seen so far (drives in-flight checks)
    bool stdver_found_ = false;
    bool service_found_ = false;
    int rank_ = 0;  // robdef.md §2.2
};

bool Parser::parse_version(std::string_view v, int line, Version& out) {
    auto parts = lex::split(v, '.');
    bool ok = parts.size() >= 2 && parts.size() <= 4;
    std::uint32_t nums[4] = {0, 0, 0, 0};
    for (std::size_t i = 0; ok && i < parts.size(); ++i) {
        if (parts[i].empty()) ok = false;
        std::uint64_t n = 0;
        for (char c : parts[i]) {
            if (!is_digit(c)) {
                ok = false;
                break;
            }
            n = n * 10 + std::uint64_t(c - '0');
            if (n > std::numeric_limits<std::uint32_t>::max()) {
                ok = false;
                break;
            }
        }
        nums[i] = static_cast<std::uint32_t>(n);
    }
    if (!ok)
        return fail(line, DiagnosticKind::version,
                    "Format error for version definition \"" + std::string(trim(v)) + "\"");
    out = Version{nums[0], nums[1], nums[2], nums[3]};
    return true;
}

void Parser::qualify(std::string& type_name) const {
    if (type_name.find('.') != std::string::npos) return;
    for (const auto& u : def_.usings) {
        if (u.unqualified_name == type_name) {
            type_name = u.qualified_name;
            return;
        }
    }
}

ParseReport Parser::run() {
    lex::LogicalLine ll;
    bool ok = true;
    while (ok && reader_.next(ll)) ok = statement(ll);
    if (ok) ok = reader_failed();
    if (ok) ok = finish_versions();
    ParseReport r;
    r.diagnostics = std::move(warnings_);
    if (failure_) {
        r.diagnostics.push_back(
            Diagnostic{Severity::error, failure_->kind, file_, failure_->line, std::move(failure_->message)});
        return r;
    }
    r.definition = std::move(def_);
    return r;
}

bool Parser::finish_versions() {
    bool version_found = stdver_found_;
    if (stdver_found_) def_.stdver = stdver_;
    // An option line above `stdver` passed the in-flight check and stays legal, as in the official
    // parser (robdef.md §2.2); canonical_text writes such options above the stdver line.
    for (std::size_t i = 0; i < def_.options.size(); ++i) {
        std::string_view o = trim_left(def_.options[i]);
        int line = i < def_.option_lines.size() ? def_.option_lines[i] : 0;
        if (o.substr(0, 7) != "version" || o.size() < 8 || !is_blank(o[7])) continue;
        if (version_found) return fail(line, DiagnosticKind::version, "Robot Raconteur version already specified");
        auto v = trim(o.substr(7));
        if (v.empty() || v.find_first_not_of("0123456789.") != std::string_view::npos || v.front() == '.' ||
            v.back() == '.' || v.find("..") != std::string_view::npos)
            return fail(line, DiagnosticKind::version, "Invalid Robot Raconteur version specified");
        Version ver;
        if (!parse_version(v, line, ver)) return false;
        def_.stdver = ver;
        def_.version_from_option = true;
        def_.version_line = line;
        version_found = true;
    }
    return true;
}

bool Parser::statement(lex::LogicalLine& ll) {
    static constexpr std::array<std::string_view, 12> kKeywords{
        "service", "stdver", "option", "import", "using", "exception",
        "constant", "enum", "struct", "object", "pod", "namedarray"};
    const int line = ll.line;
    std::string_view t = trim_left(ll.text);
    std::size_t k = 0;
    while (k < t.size() && !is_blank(t[k])) ++k;
    std::string_view kw = t.substr(0, k);
    std::string_view rest = trim(t.substr(k));
    std::size_t key = 0;
    while (key < kKeywords.size() && kKeywords[key] != kw) ++key;
    if (key == kKeywords.size() || k == t.size() || rest.empty() || !is_word(rest[0]))
        return fail(line, DiagnosticKind::syntax, "Parse error");
    if (kw != "service" && !service_found_)
        return fail(line, DiagnosticKind::ordering, "service name must be first entry in service definition");

    auto format_error = [&](std::string_view what) {
        return fail(line, DiagnosticKind::syntax,
                    "Format error for " + std::string(what) + " definition \"" + std::string(trim(ll.text)) + "\"");
    };

    if (kw == "service") {
        if (rank_ >= 1)
            return fail(line, DiagnosticKind::ordering, "service name must be first entry in service definition");
        if (!lex::is_dotted_name(rest)) return format_error("service");
        def_.name = std::string(rest);
        def_.docstring = std::move(ll.docstring);
        def_.location = loc(line);
        service_found_ = true;
        rank_ = 1;
        return true;
    }
    if (kw == "stdver") {
        if (rank_ >= 2) return fail(line, DiagnosticKind::ordering, "stdver must be first after service name");
        Version v;
        if (!parse_version(rest, line, v)) return false;
        if (v < kVersion0_9)
            return fail(line, DiagnosticKind::version,
                        "Service definition standard version 0.9 or greater required for \"stdver\" keyword");
        stdver_ = v;
        stdver_found_ = true;
        def_.version_line = line;
        return true;
    }
    if (kw == "option") {
        if (stdver_ >= kVersion0_9_2)
            return fail(line, DiagnosticKind::version, "option keyword is not support in stdver 0.9.2 or greater");
        def_.options.emplace_back(rest);
        def_.option_lines.push_back(line);
        warn(line, DiagnosticKind::deprecated, "option keyword is deprecated");
        return true;
    }
    if (kw == "import") {
        if (rank_ > 4) return fail(line, DiagnosticKind::ordering, "import must be before all but options");
        if (!lex::is_dotted_name(rest)) return format_error("import");
        def_.imports.emplace_back(rest);
        def_.import_lines.push_back(line);
        rank_ = 4;
        return true;
    }
    if (kw == "using") {
        if (rank_ > 5)
            return fail(line, DiagnosticKind::ordering,
                        "using must be after imports and before all others except options");
        // `using QUALIFIED` or `using QUALIFIED as NAME` (exactly one blank after `as`).
        std::size_t q = 0;
        while (q < rest.size() && (is_word(rest[q]) || rest[q] == '.')) ++q;
        std::string_view qualified = rest.substr(0, q);
        std::string_view tail = rest.substr(q);
        UsingDefinition u;
        bool ok = lex::is_qualified_name(qualified);
        if (ok && !tail.empty()) {
            std::size_t b = skip_blanks(tail, 0);
            ok = b > 0 && tail.substr(b, 2) == "as" && b + 3 <= tail.size() && is_blank(tail[b + 2]);
            if (ok) {
                auto alias = trim_right(tail.substr(b + 3));
                ok = lex::is_name(alias);
                u.unqualified_name = std::string(alias);
            }
        } else if (ok) {
            u.unqualified_name = std::string(lex::split_qualified(qualified).second);
        }
        if (!ok) return fail(line, DiagnosticKind::syntax, "Format error for using  definition");
        u.qualified_name = std::string(qualified);
        u.location = loc(line);
        def_.usings.push_back(std::move(u));
        rank_ = 5;
        return true;
    }
    if (kw == "exception") {
        if (rank_ >= 9) return fail(line, DiagnosticKind::ordering, "exception must be before struct and object");
        if (!lex::is_dotted_name(rest)) return format_error("exception");
        def_.exceptions.push_back(ExceptionDefinition{std::string(rest), std::move(ll.docstring), loc(line)});
        rank_ = 6;
        return true;
    }
    if (kw == "constant") {
        if (rank_ >= 9) return fail(line, DiagnosticKind::ordering, "constant must be before struct and object");
        ConstantDefinition c;
        if (!parse_constant(ll, c)) return false;
        def_.constants.push_back(std::move(c));
        rank_ = 7;
        return true;
    }
    if (kw == "enum") {
        if (rank_ >= 9) return fail(line, DiagnosticKind::ordering, "enum must be before struct and object");
        if (!parse_enum(ll)) return false;
        rank_ = 8;
        return true;
    }
    EntryKind kind = kw == "struct" ? EntryKind::structure
                     : kw == "pod"  ? EntryKind::pod
                     : kw == "namedarray" ? EntryKind::namedarray
                                          : EntryKind::object;
    if (!parse_entry(ll, kind, kw)) return false;
    rank_ = kind == EntryKind::object ? 10 : 9;
    return true;
}

bool Parser::collect_block(const lex::LogicalLine& opener, std::string_view kind, std::string_view& name,
                           std::vector<lex::LogicalLine>& body, int& end_line) {
    std::string_view t = trim_left(opener.text);
    std::size_t k = 0;
    while (k < t.size() && !is_blank(t[k])) ++k;
    name = trim(t.substr(k));
    if (!lex::is_name(name)) return fail(opener.line, DiagnosticKind::syntax, "Parse error");
    lex::LogicalLine l;
    while (reader_.next(l)) {
        std::string_view e = trim(l.text);
        if (e.substr(0, 3) == "end") {
            std::string_view word = e.substr(3);
            if (word.empty() || (is_blank(word[0]) && lex::is_word_run(trim(word)))) {
                word = trim(word);
                if (!word.empty()) {
                    if (stdver_ >= kVersion0_9_2)
                        return fail(l.line, DiagnosticKind::block,
                                    "end keyword must be only keyword on line in stdver 0.9.2 and greater");
                    if (word != kind) return fail(l.line, DiagnosticKind::block, "Block end does not match start");
                }
                end_line = l.line;
                return true;
            }
        }
        body.push_back(std::move(l));
    }
    if (!reader_failed()) return false;
    return fail(opener.line, DiagnosticKind::block, "Block end not found");
}

bool Parser::parse_enum(const lex::LogicalLine& opener) {
    std::string_view name;
    std::vector<lex::LogicalLine> body;
    int end_line = 0;
    if (!collect_block(opener, "enum", name, body, end_line)) return false;
    EnumDefinition e;
    e.name = std::string(name);
    e.docstring = opener.docstring;
    e.location = loc(opener.line);
    bool comma_endl = true;
    std::set<std::string> seen_names;
    std::set<std::int32_t> seen_values;
    for (auto& l : body) {
        if (!comma_endl) return fail(l.line, DiagnosticKind::enumeration, "Enum parse error");
        std::string_view text = trim(l.text);
        comma_endl = !text.empty() && text.back() == ',';
        while (!text.empty() && text.back() == ',') text.remove_suffix(1);
        bool first_on_line = true;
        for (auto piece : lex::split(text, ',')) {
            piece = trim(piece);
            std::size_t k = 0;
            while (k < piece.size() && is_word(piece[k])) ++k;
            std::string_view vname = piece.substr(0, k);
            if (vname.empty() || !is_alpha(vname[0])) return fail(l.line, DiagnosticKind::enumeration, "Enum parse error");
            // `end` would end the block once the value stands on its own line (canonical text).
            if (vname == "end") return fail(l.line, DiagnosticKind::enumeration, "Enum parse error");
            std::string_view rhs = trim(piece.substr(k));
            EnumValue v;
            v.name = std::string(vname);
            v.line = l.line;
            if (first_on_line) v.docstring = l.docstring;
            first_on_line = false;
            if (rhs.empty()) {
                if (e.values.empty())
                    return fail(l.line, DiagnosticKind::enumeration, "Enum first value must be specified");
                const auto& prev = e.values.back();
                if (prev.value == std::numeric_limits<std::int32_t>::max())
                    return fail(l.line, DiagnosticKind::enumeration, "Enum parse error");
                v.value = prev.value + 1;
                v.hex = prev.hex;
                v.implicit = true;
            } else {
                if (rhs[0] != '=') return fail(l.line, DiagnosticKind::enumeration, "Enum parse error");
                auto num = trim(rhs.substr(1));
                bool hex = lex::is_hex_literal(num);
                if ((!hex && !lex::is_int_literal(num)) || !integer_in_range(DataTypes::int32_t, num))
                    return fail(l.line, DiagnosticKind::enumeration, "Enum parse error");
                bool neg = num[0] == '-';
                if (num[0] == '+' || num[0] == '-') num.remove_prefix(1);
                if (hex) num.remove_prefix(2);
                std::int64_t mag = 0;
                for (char c : num) mag = mag * (hex ? 16 : 10) + (is_digit(c) ? c - '0' : (c | 0x20) - 'a' + 10);
                v.value = static_cast<std::int32_t>(neg ? -mag : mag);
                v.hex = hex;
            }
            if (!seen_names.insert(v.name).second || !seen_values.insert(v.value).second)
                return fail(l.line, DiagnosticKind::enumeration, "Enum names or values not unique");
            e.values.push_back(std::move(v));
        }
    }
    def_.enums.push_back(std::move(e));
    return true;
}

bool Parser::parse_constant(const lex::LogicalLine& ll, ConstantDefinition& c) {
    const int line = ll.line;
    std::string_view s = trim(ll.text);
    auto invalid = [&] { return fail(line, DiagnosticKind::constant, "Invalid constant definition"); };
    // `constant` TYPE NAME VALUE
    std::size_t i = 8;  // after "constant"
    if (s.substr(0, 8) != "constant" || i >= s.size() || !is_blank(s[i])) return invalid();
    i = skip_blanks(s, i);
    std::size_t k = i;
    while (k < s.size() && !is_blank(s[k])) ++k;
    std::string_view type_tok = s.substr(i, k - i);
    i = skip_blanks(s, k);
    if (i == k) return invalid();
    k = i;
    while (k < s.size() && !is_blank(s[k])) ++k;
    std::string_view name = s.substr(i, k - i);
    i = skip_blanks(s, k);
    if (i == k) return invalid();
    std::string_view value = trim(s.substr(i));
    if (value.empty() || !is_constant_type_token(type_tok) || !lex::is_name(name)) return invalid();
    std::string err;
    if (!parse_type_token(type_tok, c.type, err)) return fail(line, DiagnosticKind::syntax, err);
    if (!is_valid_constant_value(c.type, value)) return invalid();
    c.name = std::string(name);
    c.value = std::string(value);
    c.docstring = ll.docstring;
    c.location = loc(line);
    return true;
}

bool Parser::parse_member_type(std::string_view text, int line, TypeDefinition& t) {
    std::string err;
    if (!parse_type_token(text, t, err)) return fail(line, DiagnosticKind::syntax, err);
    if (t.base == DataTypes::namedtype_t) qualify(t.type_name);
    return true;
}

bool Parser::parse_member(const lex::LogicalLine& ll, std::string_view kw, ServiceEntryDefinition& e) {
    const int line = ll.line;
    MemberDefinition m;
    m.location = loc(line);
    m.docstring = ll.docstring;
    std::string msg_kw(kw == "field" ? "property" : kw);
    MemberParts p;
    if (!parse_member_parts(ll.text, p)) return fail(line, DiagnosticKind::syntax, "Could not parse " + msg_kw);
    m.name = std::string(p.name);
    const std::string trimmed(trim(ll.text));

    if (kw == "function" || kw == "callback") {
        m.kind = kw == "function" ? MemberKind::function : MemberKind::callback;
        if (!p.type || !p.params)
            return fail(line, DiagnosticKind::syntax, "Format error for " + msg_kw + " definition \"" + trimmed + "\"");
        if (!parse_member_type(*p.type, line, m.type)) return false;
        m.type.name.clear();
    } else if (kw == "event") {
        m.kind = MemberKind::event;
        if (p.type || !p.params)
            return fail(line, DiagnosticKind::syntax, "Format error for " + msg_kw + " definition \"" + trimmed + "\"");
    } else {
        m.kind = kw == "field"      ? MemberKind::field
                 : kw == "property" ? MemberKind::property
                 : kw == "objref"   ? MemberKind::objref
                 : kw == "pipe"     ? MemberKind::pipe
                 : kw == "wire"     ? MemberKind::wire
                                    : MemberKind::memory;
        if (!p.type || p.params) return fail(line, DiagnosticKind::syntax, "Format error for " + msg_kw);
        if (!parse_member_type(*p.type, line, m.type)) return false;
        m.type.name.clear();
        if (m.kind == MemberKind::objref) {
            const auto& t = m.type;
            bool ok = (t.base == DataTypes::namedtype_t || t.base == DataTypes::varobject_t);
            if (t.array == ArrayKind::array) {
                // `[]` or `[0-]` only (`[0]` is a fixed length here, though it behaves as `[]`
                // elsewhere). With an array, any container passes: the official parser checks the
                // wrong variable (robdef.md §4.1) and official clients accept such definitions.
                auto open = p.type->find('[');
                auto inner = p.type->substr(open + 1, p.type->find(']', open) - open - 1);
                ok = ok && t.array_var_length && t.array_length.empty() && (inner.empty() || inner.back() == '-');
            } else if (t.array == ArrayKind::multidimarray)
                ok = false;
            else
                ok = ok && (t.container == ContainerKind::none || t.container == ContainerKind::map_int32 ||
                            t.container == ContainerKind::map_string);
            if (!ok) return fail(line, DiagnosticKind::syntax, "Invalid objref definition \"" + trimmed + "\"");
        }
    }
    if (p.params) {
        for (auto ps : *p.params) {
            TypeDefinition pt;
            if (!parse_member_type(ps, line, pt)) return false;
            m.parameters.push_back(std::move(pt));
        }
    }
    if (p.modifiers)
        for (auto mod : *p.modifiers) m.modifiers.emplace_back(trim(mod));
    e.members.push_back(std::move(m));
    return true;
}

bool Parser::parse_entry(const lex::LogicalLine& opener, EntryKind kind, std::string_view kw) {
    std::string_view name;
    std::vector<lex::LogicalLine> body;
    int end_line = 0;
    if (!collect_block(opener, kw, name, body, end_line)) return false;
    ServiceEntryDefinition e;
    e.kind = kind;
    e.name = std::string(name);
    e.docstring = opener.docstring;
    e.location = loc(opener.line);
    static constexpr std::array<std::string_view, 13> kBodyKeywords{
        "option", "implements", "constant", "field", "property", "function", "event",
        "objref", "pipe", "callback", "wire", "memory", "end"};
    for (auto& l : body) {
        const int line = l.line;
        std::string_view t = trim_left(l.text);
        std::size_t k = 0;
        while (k < t.size() && !is_blank(t[k])) ++k;
        std::string_view bkw = t.substr(0, k);
        std::string_view rest = trim(t.substr(k));
        std::size_t key = 0;
        while (key < kBodyKeywords.size() && kBodyKeywords[key] != bkw) ++key;
        if (key == kBodyKeywords.size() || k == t.size() || rest.empty() || !is_word(rest[0]))
            return fail(line, DiagnosticKind::syntax, "Parse error");
        if (kind != EntryKind::object && key >= 4 && bkw != "end")
            return fail(line, DiagnosticKind::syntax, "Structures must only contain fields, constants, and options");
        if (bkw == "option") {
            if (stdver_ >= kVersion0_9_2)
                return fail(line, DiagnosticKind::version, "option keyword is not support in stdver 0.9.2 or greater");
            e.options.emplace_back(rest);
            e.option_lines.push_back(line);
            warn(line, DiagnosticKind::deprecated, "option keyword is deprecated");
        } else if (bkw == "implements") {
            if (!e.members.empty())
                return fail(line, DiagnosticKind::ordering, "Structure implements must come before members");
            if (kind != EntryKind::object)
                return fail(line, DiagnosticKind::syntax,
                            "Structures must only contain fields, constants, and options");
            if (!lex::is_dotted_name(rest))
                return fail(line, DiagnosticKind::syntax,
                            "Format error for implements definition \"" + std::string(trim(l.text)) + "\"");
            std::string imp(rest);
            qualify(imp);
            e.implements.push_back(std::move(imp));
            e.implements_lines.push_back(line);
        } else if (bkw == "constant") {
            if (!e.members.empty())
                return fail(line, DiagnosticKind::ordering, "Structure constants must come before members");
            ConstantDefinition c;
            if (!parse_constant(l, c)) return false;
            e.constants.push_back(std::move(c));
        } else if (bkw == "field") {
            if (kind == EntryKind::object)
                return fail(line, DiagnosticKind::syntax, "Objects cannot contain fields, use properties instead");
            if (!parse_member(l, bkw, e)) return false;
        } else if (bkw == "end") {
            return fail(line, DiagnosticKind::syntax, "Parse error");
        } else {
            if (!parse_member(l, bkw, e)) return false;
        }
    }
    switch (kind) {
        case EntryKind::structure: def_.structures.push_back(std::move(e)); break;
        case EntryKind::pod: def_.pods.push_back(std::move(e)); break;
        case EntryKind::namedarray: def_.namedarrays.push_back(std::move(e)); break;
        case EntryKind::object: def_.objects.push_back(std::move(e)); break;
    }
    return true;
}

}  // namespace

ParseReport parse_service_definition_report(std::string_view text, std::string_view file_name) {
    Parser p(text, file_name);
    return p.run();
}

Result<ParseOutput> parse_service_definition(std::string_view text, std::string_view file_name) {
    ParseReport r = parse_service_definition_report(text, file_name);
    if (!r.ok()) {
        const Diagnostic& d = r.diagnostics.back();
        std::string msg = d.file.empty() ? std::string("<text>") : d.file;
        if (d.line > 0) {
            msg += ':';
            msg += std::to_string(d.line);
        }
        msg += ": ";
        msg += d.message;
        return fail(MessageErrorType::ServiceDefinitionError, std::move(msg));
    }
    ParseOutput out{std::move(*r.definition), std::move(r.diagnostics)};
    return out;
}

Result<TypeDefinition> parse_type(std::string_view text) {
    TypeDefinition t;
    std::string err;
    if (!parse_type_token(text, t, err)) return fail(MessageErrorType::ServiceDefinitionError, std::move(err));
    return t;
}

}  // namespace rr::robdef
