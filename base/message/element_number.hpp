// Element numbers in message format 2 (wire.md §1.4): v2 has no number field, so an element number
// travels as its decimal text in ElementName. Only the canonical text round-trips byte-identically,
// so only canonical text is read back as a number: an optional '-', then "0" or digits without a
// leading zero, within int32 range, and never "-0".
#pragma once

#include <array>
#include <charconv>
#include <cstdint>
#include <optional>
#include <string_view>

namespace rr {

/// The number whose canonical decimal text is `name`, or nullopt.
constexpr std::optional<std::int32_t> parse_element_number(std::string_view name) noexcept {
    if (name.empty() || name.size() > 11) return std::nullopt;
    bool negative = name.front() == '-';
    std::string_view digits = negative ? name.substr(1) : name;
    if (digits.empty() || (digits.size() > 1 && digits.front() == '0')) return std::nullopt;
    if (negative && digits == "0") return std::nullopt;
    std::int64_t v = 0;
    for (char c : digits) {
        if (c < '0' || c > '9') return std::nullopt;
        v = v * 10 + (c - '0');
    }
    if (negative) v = -v;
    if (v < INT32_MIN || v > INT32_MAX) return std::nullopt;
    return static_cast<std::int32_t>(v);
}

/// Canonical decimal text of an element number ("-2147483648" is the longest: 11 characters).
class ElementNumberText {
public:
    explicit ElementNumberText(std::int32_t number) noexcept {
        auto r = std::to_chars(buf_.data(), buf_.data() + buf_.size(), number);
        size_ = static_cast<std::size_t>(r.ptr - buf_.data());
    }
    std::string_view view() const noexcept { return {buf_.data(), size_}; }

private:
    std::array<char, 12> buf_{};
    std::size_t size_ = 0;
};

}  // namespace rr
