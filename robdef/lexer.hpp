// Lexical layer of the service definition language (robdef.md §1): physical lines, line
// continuation, comments, docstrings, the character set, and the small token grammars (names,
// numbers) shared by the parser and the verifier. Hand-written; no regex.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "robdef/diagnostic.hpp"

namespace rr::robdef::lex {

constexpr bool is_blank(char c) noexcept { return c == ' ' || c == '\t'; }
constexpr bool is_digit(char c) noexcept { return c >= '0' && c <= '9'; }
constexpr bool is_alpha(char c) noexcept { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z'); }
constexpr bool is_alnum(char c) noexcept { return is_alpha(c) || is_digit(c); }
/// `\w`: letter, digit or underscore.
constexpr bool is_word(char c) noexcept { return is_alnum(c) || c == '_'; }
constexpr bool is_hex_digit(char c) noexcept {
    return is_digit(c) || (c >= 'a' && c <= 'f') || (c >= 'A' && c <= 'F');
}
/// TAB or printable ASCII 0x20–0x7E (robdef.md §1.1).
constexpr bool is_valid_char(char c) noexcept { return c == '\t' || (c >= 0x20 && c <= 0x7e); }

std::string_view trim(std::string_view s) noexcept;
std::string_view trim_left(std::string_view s) noexcept;
std::string_view trim_right(std::string_view s) noexcept;

/// NAME: a letter, then word characters, not ending in `_` (robdef.md §2.1).
bool is_name(std::string_view s) noexcept;
/// DOTTED: NAME ( `.` NAME )*.
bool is_dotted_name(std::string_view s) noexcept;
/// QUALIFIED: NAME ( `.` NAME )+.
bool is_qualified_name(std::string_view s) noexcept;
/// `\w+`.
bool is_word_run(std::string_view s) noexcept;
/// Decimal integer `[+-]?(0|[1-9][0-9]*)`.
bool is_int_literal(std::string_view s) noexcept;
/// Hex integer `[+-]?0x[0-9a-fA-F]+`.
bool is_hex_literal(std::string_view s) noexcept;
/// Float `[+-]?((0|[1-9][0-9]*)(\.[0-9]*)?|\.[0-9]+)([eE][+-]?[0-9]+)?` (robdef.md §7).
bool is_float_literal(std::string_view s) noexcept;
/// Any of the three number forms (modifier arguments).
bool is_number_literal(std::string_view s) noexcept;

/// Splits `a.b.C` at the last dot: {"a.b", "C"}; {"", s} when there is no dot.
std::pair<std::string_view, std::string_view> split_qualified(std::string_view s) noexcept;

/// Splits on a separator character (no trimming).
std::vector<std::string_view> split(std::string_view s, char sep);

/// One logical line of code (not blank, not a comment, not a docstring), with the `##` lines that
/// precede it (robdef.md §1.3).
struct LogicalLine {
    std::string text;                    ///< continuation lines joined (robdef.md §1.2)
    int line = 0;                        ///< physical line where the logical line starts
    std::vector<std::string> docstring;  ///< text after `##` of the pending docstring lines
};

/// Pulls logical lines from a definition text. Errors (NUL, non-ASCII, continuation on the last
/// line) are reported once, at the physical line where they occur; after an error next() returns
/// false and error() is set.
class LineReader {
public:
    explicit LineReader(std::string_view text) noexcept : text_(text) {}

    /// Next code line; false at the end of the text or on error.
    bool next(LogicalLine& out);
    const std::optional<std::pair<int, std::string>>& error() const noexcept { return error_; }
    /// Number of the last physical line read.
    int physical_line() const noexcept { return line_; }

private:
    bool read_physical(std::string_view& out);
    bool check_chars(std::string_view l);

    std::string_view text_;
    std::size_t pos_ = 0;
    int line_ = 0;
    std::optional<std::pair<int, std::string>> error_;
};

}  // namespace rr::robdef::lex
