#include "robdef/lexer.hpp"

#include "robdef/parser.hpp"

namespace rr::robdef::lex {

std::string_view trim_left(std::string_view s) noexcept {
    std::size_t i = 0;
    while (i < s.size() && is_blank(s[i])) ++i;
    return s.substr(i);
}

std::string_view trim_right(std::string_view s) noexcept {
    std::size_t n = s.size();
    while (n > 0 && is_blank(s[n - 1])) --n;
    return s.substr(0, n);
}

std::string_view trim(std::string_view s) noexcept { return trim_right(trim_left(s)); }

bool is_name(std::string_view s) noexcept {
    if (s.empty() || !is_alpha(s.front()) || s.back() == '_') return false;
    for (char c : s)
        if (!is_word(c)) return false;
    return true;
}

bool is_dotted_name(std::string_view s) noexcept {
    if (s.empty()) return false;
    for (auto part : split(s, '.'))
        if (!is_name(part)) return false;
    return true;
}

bool is_qualified_name(std::string_view s) noexcept {
    return s.find('.') != std::string_view::npos && is_dotted_name(s);
}

bool is_word_run(std::string_view s) noexcept {
    if (s.empty()) return false;
    for (char c : s)
        if (!is_word(c)) return false;
    return true;
}

namespace {

std::string_view skip_sign(std::string_view s) noexcept {
    if (!s.empty() && (s[0] == '+' || s[0] == '-')) s.remove_prefix(1);
    return s;
}

// Decimal integer without sign: 0 or [1-9][0-9]*; returns the length matched (0 = no match).
std::size_t match_unsigned_int(std::string_view s) noexcept {
    if (s.empty() || !is_digit(s[0])) return 0;
    if (s[0] == '0') return 1;
    std::size_t i = 1;
    while (i < s.size() && is_digit(s[i])) ++i;
    return i;
}

}  // namespace

bool is_int_literal(std::string_view s) noexcept {
    s = skip_sign(s);
    return !s.empty() && match_unsigned_int(s) == s.size();
}

bool is_hex_literal(std::string_view s) noexcept {
    s = skip_sign(s);
    if (s.size() < 3 || s[0] != '0' || s[1] != 'x') return false;
    for (std::size_t i = 2; i < s.size(); ++i)
        if (!is_hex_digit(s[i])) return false;
    return true;
}

bool is_float_literal(std::string_view s) noexcept {
    s = skip_sign(s);
    std::size_t i = 0;
    if (!s.empty() && s[0] == '.') {
        i = 1;
        std::size_t start = i;
        while (i < s.size() && is_digit(s[i])) ++i;
        if (i == start) return false;
    } else {
        i = match_unsigned_int(s);
        if (i == 0) return false;
        if (i < s.size() && s[i] == '.') {
            ++i;
            while (i < s.size() && is_digit(s[i])) ++i;
        }
    }
    if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
        ++i;
        if (i < s.size() && (s[i] == '+' || s[i] == '-')) ++i;
        std::size_t start = i;
        while (i < s.size() && is_digit(s[i])) ++i;
        if (i == start) return false;
    }
    return i == s.size();
}

bool is_number_literal(std::string_view s) noexcept {
    return is_int_literal(s) || is_hex_literal(s) || is_float_literal(s);
}

std::pair<std::string_view, std::string_view> split_qualified(std::string_view s) noexcept {
    auto dot = s.rfind('.');
    if (dot == std::string_view::npos) return {std::string_view{}, s};
    return {s.substr(0, dot), s.substr(dot + 1)};
}

std::vector<std::string_view> split(std::string_view s, char sep) {
    std::vector<std::string_view> out;
    std::size_t start = 0;
    while (true) {
        auto p = s.find(sep, start);
        if (p == std::string_view::npos) {
            out.push_back(s.substr(start));
            break;
        }
        out.push_back(s.substr(start, p - start));
        start = p + 1;
    }
    return out;
}

bool LineReader::read_physical(std::string_view& out) {
    if (pos_ >= text_.size()) return false;
    auto nl = text_.find('\n', pos_);
    std::string_view l;
    if (nl == std::string_view::npos) {
        l = text_.substr(pos_);
        pos_ = text_.size();
    } else {
        l = text_.substr(pos_, nl - pos_);
        pos_ = nl + 1;
    }
    while (!l.empty() && l.back() == '\r') l.remove_suffix(1);
    ++line_;
    out = l;
    return true;
}

bool LineReader::check_chars(std::string_view l) {
    if (l.find('\0') != std::string_view::npos) {
        error_.emplace(line_, "Service definition must not contain null characters");
        return false;
    }
    for (std::size_t i = 0; i < l.size(); ++i) {
        if (!is_valid_char(l[i])) {
            std::string message = "Service definition must contain only ASCII characters";
            // The official message, and what the bytes are when they are a byte-order mark: editors
            // add it unseen, and the official parser refuses text that starts with one too.
            if (l.substr(i, kUtf8ByteOrderMark.size()) == kUtf8ByteOrderMark)
                message += " (a UTF-8 byte-order mark, bytes EF BB BF, at column " + std::to_string(i + 1) + ")";
            error_.emplace(line_, std::move(message));
            return false;
        }
    }
    return true;
}

bool LineReader::next(LogicalLine& out) {
    if (error_) return false;
    std::vector<std::string> doc;
    bool blank_seen = false;
    std::string_view l;
    while (read_physical(l)) {
        if (!check_chars(l)) return false;
        auto t = trim_left(l);
        if (t.size() >= 2 && t[0] == '#' && t[1] == '#') {
            if (blank_seen) {
                doc.clear();
                blank_seen = false;
            }
            doc.emplace_back(t.substr(2));
            continue;
        }
        if (!t.empty() && t[0] == '#') {
            doc.clear();
            continue;
        }
        if (t.empty()) {
            blank_seen = true;
            continue;
        }
        out.line = line_;
        out.text.assign(l);
        while (!out.text.empty() && out.text.back() == '\\') {
            out.text.back() = ' ';
            std::string_view cont;
            if (!read_physical(cont)) {
                error_.emplace(line_, "Service definition line continuation must not be on last line");
                return false;
            }
            if (!check_chars(cont)) return false;
            out.text.append(cont);
        }
        out.docstring = std::move(doc);
        return true;
    }
    return false;
}

}  // namespace rr::robdef::lex
