#include "core/json/element_json_text.hpp"

#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>

#include <nlohmann/json.hpp>

#include "core/json/json_numbers.hpp"
#include "core/value/element_layout.hpp"
#include "core/value/numeric_array.hpp"

namespace rr::element_json_text {

using robdef::ArrayKind;
using robdef::ContainerKind;

namespace {

char* put(char* out, std::string_view s) {
    std::memcpy(out, s.data(), s.size());
    return out + s.size();
}

// As json_numbers::to_json(double) dumps: the shortest round-trip text nlohmann writes (the same
// function its serializer calls), non-finite values as strings.
char* put_real(char* out, double d) {
    if (std::isnan(d)) return put(out, "\"NaN\"");
    if (std::isinf(d)) return put(out, d > 0 ? "\"Infinity\"" : "\"-Infinity\"");
    return nlohmann::detail::to_chars(out, out + 64, d);
}

// The most characters put_item writes for a T: a real's shortest text is at most 24
// ("-2.2250738585072014e-308"), a 64-bit integer beyond 2^53 a quoted 20 digits.
template <class T>
constexpr std::size_t max_item_chars() {
    if constexpr (std::is_same_v<T, bool>)
        return 5;
    else if constexpr (detail::is_complex_v<T>)
        return 6 + 24 + 6 + 24 + 1;
    else if constexpr (std::is_floating_point_v<T>)
        return 24;
    else
        return std::numeric_limits<T>::digits10 + 1 + (std::is_signed_v<T> ? 1 : 0) + (sizeof(T) == 8 ? 2 : 0);
}

template <class T>
char* put_item(char* out, T v) {
    if constexpr (std::is_same_v<T, bool>) {
        return put(out, v ? "true" : "false");
    } else if constexpr (detail::is_complex_v<T>) {
        // nlohmann's objects keep their keys sorted: "im" before "re".
        out = put(out, "{\"im\":");
        out = put_real(out, static_cast<double>(v.imag()));
        out = put(out, ",\"re\":");
        out = put_real(out, static_cast<double>(v.real()));
        return put(out, "}");
    } else if constexpr (std::is_floating_point_v<T>) {
        return put_real(out, static_cast<double>(v));
    } else {
        constexpr auto kExact = json_numbers::kMaxExactInteger;
        bool exact = true;
        if constexpr (sizeof(T) == 8) {
            if constexpr (std::is_signed_v<T>)
                exact = v >= -static_cast<T>(kExact) && v <= static_cast<T>(kExact);
            else
                exact = v <= kExact;
        }
        if (exact) return std::to_chars(out, out + 24, v).ptr;
        *out++ = '"';
        out = std::to_chars(out, out + 24, v).ptr;
        *out++ = '"';
        return out;
    }
}

template <class T>
void append_items(std::string& out, const std::byte* data, std::size_t n, bool scalar) {
    const std::size_t at = out.size();
    out.resize(at + n * (max_item_chars<T>() + 1) + 2);
    char* p = out.data() + at;
    if (!scalar) *p++ = '[';
    for (std::size_t i = 0; i < n; ++i) {
        if (i) *p++ = ',';
        p = put_item(p, detail::load_item<T>(data + i * sizeof(T)));  // received bytes: any alignment
    }
    if (!scalar) *p++ = ']';
    out.resize(static_cast<std::size_t>(p - out.data()));
}

}  // namespace

bool renders(const robdef::TypeDefinition& type) noexcept {
    return type.container == ContainerKind::none && is_numeric(type.base) &&
           (type.array == ArrayKind::none || type.array == ArrayKind::array);
}

bool append(std::string& out, const MessageElement& element, const robdef::TypeDefinition& type) {
    if (!renders(type) || element.type != type.base) return false;
    const std::size_t item = data_type_size(type.base);
    if (element.data.size() % item != 0) return false;
    const std::size_t n = element.data.size() / item;
    if (!check_count(n, type)) return false;
    dispatch_numeric(type.base, [&](auto tag) {
        using T = typename decltype(tag)::type;
        append_items<T>(out, element.data.data(), n, type.array == ArrayKind::none);
    });
    return true;
}

void append_number(std::string& out, DataTypes type, const std::byte* item) {
    dispatch_numeric(type, [&](auto tag) {
        using T = typename decltype(tag)::type;
        char text[64];  // put_real hands nlohmann 64 characters of room
        out.append(text, put_item(text, detail::load_item<T>(item)));
    });
}

}  // namespace rr::element_json_text
