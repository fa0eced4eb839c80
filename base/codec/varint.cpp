#include "base/codec/varint.hpp"

namespace rr {

// Values above 252 only: write_uint_x writes the one-byte form inline.
void detail::write_uint_x_multibyte(ByteWriter& w, std::uint32_t v) {
    if (v <= 0xFFFF) {
        w.write_u8(253);
        w.write_u16(static_cast<std::uint16_t>(v));
    } else {
        w.write_u8(254);
        w.write_u32(v);
    }
}

void write_uint_x64(ByteWriter& w, std::uint64_t v) {
    if (v <= 0xFFFFFFFFu) return write_uint_x(w, static_cast<std::uint32_t>(v));
    w.write_u8(255);
    w.write_u64(v);
}

void write_int_x(ByteWriter& w, std::int32_t v) {
    if (v >= -128 && v <= 124) {
        w.write_i8(static_cast<std::int8_t>(v));
    } else if (v >= -32768 && v <= 32767) {
        w.write_i8(125);
        w.write_i16(static_cast<std::int16_t>(v));
    } else {
        w.write_i8(126);
        w.write_i32(v);
    }
}

void write_int_x64(ByteWriter& w, std::int64_t v) {
    if (v >= std::numeric_limits<std::int32_t>::min() && v <= std::numeric_limits<std::int32_t>::max())
        return write_int_x(w, static_cast<std::int32_t>(v));
    w.write_i8(127);
    w.write_i64(v);
}

namespace {

// Shared body of the unsigned readers; `allow64` selects whether marker 255 is accepted.
Result<std::uint64_t> read_uint_x_body(ByteReader& r, bool allow64) {
    auto first = r.read_u8();
    if (!first) return first.take_error();
    switch (*first) {
        case 253: {
            auto v = r.read_u16();
            if (!v) return v.take_error();
            return std::uint64_t{*v};
        }
        case 254: {
            auto v = r.read_u32();
            if (!v) return v.take_error();
            return std::uint64_t{*v};
        }
        case 255: {
            if (!allow64) return fail(MessageErrorType::ProtocolError, "uint_x: 64-bit form in a 32-bit field");
            auto v = r.read_u64();
            if (!v) return v.take_error();
            return *v;
        }
        default: return std::uint64_t{*first};
    }
}

Result<std::int64_t> read_int_x_body(ByteReader& r, bool allow64) {
    auto first = r.read_i8();
    if (!first) return first.take_error();
    switch (*first) {
        case 125: {
            auto v = r.read_i16();
            if (!v) return v.take_error();
            return std::int64_t{*v};
        }
        case 126: {
            auto v = r.read_i32();
            if (!v) return v.take_error();
            return std::int64_t{*v};
        }
        case 127: {
            if (!allow64) return fail(MessageErrorType::ProtocolError, "int_x: 64-bit form in a 32-bit field");
            auto v = r.read_i64();
            if (!v) return v.take_error();
            return *v;
        }
        default: return std::int64_t{*first};
    }
}

// The cursor is committed back only on success.
Result<std::uint64_t> read_uint_x_any(ByteReader& in, bool allow64) {
    ByteReader r = in;
    auto v = read_uint_x_body(r, allow64);
    if (v) in = r;
    return v;
}

Result<std::int64_t> read_int_x_any(ByteReader& in, bool allow64) {
    ByteReader r = in;
    auto v = read_int_x_body(r, allow64);
    if (v) in = r;
    return v;
}

}  // namespace

Result<std::uint32_t> detail::read_uint_x_multibyte(ByteReader& r) {
    auto v = read_uint_x_any(r, false);
    if (!v) return v.take_error();
    return static_cast<std::uint32_t>(*v);
}

Result<std::uint64_t> read_uint_x64(ByteReader& r) { return read_uint_x_any(r, true); }

Result<std::int32_t> read_int_x(ByteReader& r) {
    auto v = read_int_x_any(r, false);
    if (!v) return v.take_error();
    return static_cast<std::int32_t>(*v);
}

Result<std::int64_t> read_int_x64(ByteReader& r) { return read_int_x_any(r, true); }

}  // namespace rr
