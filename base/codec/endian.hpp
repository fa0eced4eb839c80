// Little-endian loads and stores by shifts (wire.md §1.1: every integer on the wire is little-endian).
// No reinterpret_cast of received bytes: values are assembled byte by byte, which compilers fold into
// single loads/stores on little-endian targets.
#pragma once

#include "base/codec/bit_cast.hpp"
#include <bit>
#include <cstddef>
#include <cstdint>
#include <type_traits>

namespace rr {

/// Reads an unsigned or signed integer of sizeof(T) bytes from `p` (little-endian). `p` must point
/// at sizeof(T) readable bytes.
template <class T>
constexpr T load_le(const std::byte* p) noexcept {
    static_assert(std::is_integral_v<T>);
    using U = std::make_unsigned_t<T>;
    U v = 0;
    for (std::size_t i = 0; i < sizeof(T); ++i) v |= static_cast<U>(static_cast<U>(p[i]) << (8 * i));
    return static_cast<T>(v);
}

/// Writes `value` as sizeof(T) little-endian bytes to `p`.
template <class T>
constexpr void store_le(std::byte* p, T value) noexcept {
    static_assert(std::is_integral_v<T>);
    using U = std::make_unsigned_t<T>;
    auto v = static_cast<U>(value);
    for (std::size_t i = 0; i < sizeof(T); ++i) p[i] = static_cast<std::byte>((v >> (8 * i)) & 0xFFu);
}

/// IEEE-754 values travel as their bit patterns, little-endian.
inline double load_le_double(const std::byte* p) noexcept { return rr::bit_cast<double>(load_le<std::uint64_t>(p)); }
inline float load_le_float(const std::byte* p) noexcept { return rr::bit_cast<float>(load_le<std::uint32_t>(p)); }
inline void store_le_double(std::byte* p, double v) noexcept { store_le(p, rr::bit_cast<std::uint64_t>(v)); }
inline void store_le_float(std::byte* p, float v) noexcept { store_le(p, rr::bit_cast<std::uint32_t>(v)); }

}  // namespace rr
