#include <catch2/catch.hpp>

#include <cstdint>
#include <limits>
#include <vector>

#include "base/codec/varint.hpp"

using namespace rr;

namespace {

std::vector<std::byte> bytes(std::initializer_list<int> in) {
    std::vector<std::byte> out;
    for (int v : in) out.push_back(static_cast<std::byte>(v));
    return out;
}

std::vector<std::byte> encode_u(std::uint32_t v) {
    std::vector<std::byte> out;
    ByteWriter w(out);
    write_uint_x(w, v);
    return out;
}

std::vector<std::byte> encode_i(std::int32_t v) {
    std::vector<std::byte> out;
    ByteWriter w(out);
    write_int_x(w, v);
    return out;
}

}  // namespace

// wire.md §15.1, left column.
TEST_CASE("codec: uint_x table of wire.md 15.1") {
    struct Row {
        std::uint32_t value;
        std::vector<std::byte> wire;
    };
    const Row rows[] = {
        {0, bytes({0x00})},
        {252, bytes({0xfc})},
        {253, bytes({0xfd, 0xfd, 0x00})},
        {65535, bytes({0xfd, 0xff, 0xff})},
        {65536, bytes({0xfe, 0x00, 0x00, 0x01, 0x00})},
        {4294967295u, bytes({0xfe, 0xff, 0xff, 0xff, 0xff})},
    };
    for (const auto& row : rows) {
        INFO("value " << row.value);
        CHECK(encode_u(row.value) == row.wire);
        CHECK(uint_x_size(row.value) == row.wire.size());
        ByteReader r(row.wire);
        auto v = read_uint_x(r);
        REQUIRE(v);
        CHECK(*v == row.value);
        CHECK(r.at_end());
    }
}

// wire.md §15.1, right column.
TEST_CASE("codec: int_x table of wire.md 15.1") {
    struct Row {
        std::int32_t value;
        std::vector<std::byte> wire;
    };
    const Row rows[] = {
        {0, bytes({0x00})},
        {124, bytes({0x7c})},
        {125, bytes({0x7d, 0x7d, 0x00})},
        {-1, bytes({0xff})},
        {-128, bytes({0x80})},
        {-129, bytes({0x7d, 0x7f, 0xff})},
        {32767, bytes({0x7d, 0xff, 0x7f})},
        {32768, bytes({0x7e, 0x00, 0x80, 0x00, 0x00})},
        {std::numeric_limits<std::int32_t>::min(), bytes({0x7e, 0x00, 0x00, 0x00, 0x80})},
    };
    for (const auto& row : rows) {
        INFO("value " << row.value);
        CHECK(encode_i(row.value) == row.wire);
        CHECK(int_x_size(row.value) == row.wire.size());
        ByteReader r(row.wire);
        auto v = read_int_x(r);
        REQUIRE(v);
        CHECK(*v == row.value);
        CHECK(r.at_end());
    }
}

TEST_CASE("codec: 64-bit varint forms") {
    std::vector<std::byte> out;
    ByteWriter w(out);
    write_uint_x64(w, 0x100000000ull);
    CHECK(out == bytes({0xff, 0x00, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00}));
    CHECK(uint_x64_size(0x100000000ull) == 9);
    CHECK(uint_x64_size(65536) == 5);
    {
        ByteReader r(out);
        CHECK(*read_uint_x64(r) == 0x100000000ull);
    }
    {
        ByteReader r(out);  // the 32-bit reader rejects the 64-bit marker and keeps its cursor
        auto v = read_uint_x(r);
        REQUIRE_FALSE(v);
        CHECK(v.error().type == MessageErrorType::ProtocolError);
        CHECK(r.position() == 0);
    }
    out.clear();
    write_int_x64(w, -0x100000000ll);
    CHECK(out.size() == 9);
    CHECK(out[0] == std::byte{0x7f});
    CHECK(int_x64_size(-0x100000000ll) == 9);
    {
        ByteReader r(out);
        CHECK(*read_int_x64(r) == -0x100000000ll);
    }
    {
        ByteReader r(out);
        CHECK_FALSE(read_int_x(r));
    }
    out.clear();
    write_int_x64(w, -5);
    CHECK(out == bytes({0xfb}));
}

TEST_CASE("codec: varint readers reject truncation and accept longer-than-needed forms") {
    for (auto wire : {bytes({0xfd}), bytes({0xfd, 0x01}), bytes({0xfe, 1, 2, 3}), bytes({})}) {
        ByteReader r(wire);
        auto v = read_uint_x(r);
        REQUIRE_FALSE(v);
        CHECK(v.error().type == MessageErrorType::ProtocolError);
        CHECK(r.position() == 0);
    }
    for (auto wire : {bytes({0x7d, 0x01}), bytes({0x7e, 1, 2, 3})}) {
        ByteReader r(wire);
        CHECK_FALSE(read_int_x(r));
    }
    auto longer = bytes({0xfe, 0x05, 0x00, 0x00, 0x00});
    ByteReader r(longer);
    CHECK(*read_uint_x(r) == 5);
}

TEST_CASE("codec: self-inclusive sizes (GetSizePlusUintX)") {
    CHECK(size_plus_uint_x(0) == 1);
    CHECK(size_plus_uint_x(251) == 252);  // total 252 still fits one byte
    CHECK(size_plus_uint_x(252) == 255);  // total 253 would not: 3-byte form
    CHECK(size_plus_uint_x(65532) == 65535);
    CHECK(size_plus_uint_x(65533) == 65538);
    CHECK(size_plus_uint_x(0xFFFFFFFAull) == 0xFFFFFFFFull);
    CHECK(size_plus_uint_x(0xFFFFFFFBull) > 0xFFFFFFFFull);
    // Property: the width of the total equals the width that was added.
    for (std::uint64_t s : {0ull, 10ull, 250ull, 251ull, 252ull, 253ull, 1000ull, 65531ull, 65532ull, 65533ull,
                            70000ull, 0xFFFFFFF0ull}) {
        auto total = size_plus_uint_x(s);
        CHECK(total - s == uint_x_size(static_cast<std::uint32_t>(total)));
    }
}
