// Variable-length integers of message format 4 (wire.md §2.2; CORE IOUtils.cpp).
//
// uint_x: first byte 0–252 is the value; 253 → uint16 follows; 254 → uint32 follows; 255 → uint64
// follows (64-bit fields only: the 32-bit reader rejects it with ProtocolError).
// int_x:  first byte as int8 −128…124 is the value; 125 → int16; 126 → int32; 127 → int64 (64-bit
// fields only).
// Writers always use the shortest form. Readers accept longer-than-needed forms (as CORE does), so a
// re-encoded message is byte-identical only when the input used shortest forms, which CORE always does.
// Every message-format-4 field is a 32-bit varint; the 64-bit forms are here for completeness.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>

#include "base/codec/byte_reader.hpp"
#include "base/codec/byte_writer.hpp"

namespace rr {

/// Encoded byte count of `v` as uint_x: 1, 3 or 5.
constexpr std::size_t uint_x_size(std::uint32_t v) noexcept { return v <= 252 ? 1 : v <= 0xFFFF ? 3 : 5; }
/// Encoded byte count of `v` as 64-bit uint_x: 1, 3, 5 or 9.
constexpr std::size_t uint_x64_size(std::uint64_t v) noexcept {
    return v <= 0xFFFFFFFFu ? uint_x_size(static_cast<std::uint32_t>(v)) : 9;
}
/// Encoded byte count of `v` as int_x: 1, 3 or 5.
constexpr std::size_t int_x_size(std::int32_t v) noexcept {
    return (v >= -128 && v <= 124) ? 1 : (v >= -32768 && v <= 32767) ? 3 : 5;
}
/// Encoded byte count of `v` as 64-bit int_x: 1, 3, 5 or 9.
constexpr std::size_t int_x64_size(std::int64_t v) noexcept {
    return (v >= std::numeric_limits<std::int32_t>::min() && v <= std::numeric_limits<std::int32_t>::max())
               ? int_x_size(static_cast<std::int32_t>(v))
               : 9;
}

/// Self-inclusive size (wire.md §2.2, CORE GetSizePlusUintX): given `s`, the bytes after a uint_x size
/// field, returns s plus the width of the uint_x that encodes the total. The result fits a 32-bit
/// uint_x only if it is ≤ 0xFFFFFFFF; callers check that (s > 0xFFFFFFFA gives a larger value).
constexpr std::uint64_t size_plus_uint_x(std::uint64_t s) noexcept {
    if (s <= 251) return s + 1;
    if (s <= 0xFFFFu - 3) return s + 3;
    if (s <= 0xFFFFFFFFu - 5) return s + 5;
    return s + 9;
}

namespace detail {
void write_uint_x_multibyte(ByteWriter& w, std::uint32_t v);
Result<std::uint32_t> read_uint_x_multibyte(ByteReader& r);
}  // namespace detail

// The one-byte form (every value up to 252: most sizes, counts and flags) is inline; messages carry
// about ten of these per entry.
inline void write_uint_x(ByteWriter& w, std::uint32_t v) {
    if (v <= 252)
        w.write_u8(static_cast<std::uint8_t>(v));
    else
        detail::write_uint_x_multibyte(w, v);
}
void write_uint_x64(ByteWriter& w, std::uint64_t v);
void write_int_x(ByteWriter& w, std::int32_t v);
void write_int_x64(ByteWriter& w, std::int64_t v);

/// Reads a 32-bit uint_x. Errors: ProtocolError (truncated, or the 64-bit marker 255).
/// On error the cursor is left where it was (as for every read below).
inline Result<std::uint32_t> read_uint_x(ByteReader& r) {
    if (r.remaining() != 0) {
        const auto first = static_cast<std::uint8_t>(r.bytes()[r.position()]);
        if (first <= 252) {
            (void)r.skip(1);
            return first;
        }
    }
    return detail::read_uint_x_multibyte(r);
}
/// Reads a 64-bit uint_x. Errors: ProtocolError (truncated).
Result<std::uint64_t> read_uint_x64(ByteReader& r);
/// Reads a 32-bit int_x. Errors: ProtocolError (truncated, or the 64-bit marker 127).
Result<std::int32_t> read_int_x(ByteReader& r);
/// Reads a 64-bit int_x. Errors: ProtocolError (truncated).
Result<std::int64_t> read_int_x64(ByteReader& r);

}  // namespace rr
