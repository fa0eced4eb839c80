#include <catch2/catch.hpp>

#include <vector>

#include "base/codec/byte_reader.hpp"
#include "base/codec/byte_writer.hpp"

using namespace rr;

TEST_CASE("codec: ByteWriter appends little-endian integers that ByteReader reads back") {
    std::vector<std::byte> out{std::byte{0x99}};
    ByteWriter w(out);
    w.write_u16(0x1234);
    w.write_i32(-2);
    w.write_u64(0x0102030405060708ull);
    w.write_string("RRAC");
    CHECK(w.written() == 2 + 4 + 8 + 4);
    REQUIRE(out.size() == 19);
    CHECK(out[0] == std::byte{0x99});
    CHECK(out[1] == std::byte{0x34});
    CHECK(out[2] == std::byte{0x12});
    CHECK(out[3] == std::byte{0xfe});
    CHECK(out[6] == std::byte{0xff});
    CHECK(out[7] == std::byte{0x08});
    ByteReader r(std::span<const std::byte>(out).subspan(1));
    CHECK(*r.read_u16() == 0x1234);
    CHECK(*r.read_i32() == -2);
    CHECK(*r.read_u64() == 0x0102030405060708ull);
    CHECK(*r.read_string(4) == "RRAC");
}

TEST_CASE("codec: float bit patterns round-trip little-endian") {
    std::array<std::byte, 8> b{};
    store_le_double(b.data(), 42.345);
    CHECK(b[0] == std::byte{0x5c});  // wire.md §15.2: 42.345 = 5c 8f c2 f5 28 2c 45 40
    CHECK(b[7] == std::byte{0x40});
    CHECK(load_le_double(b.data()) == 42.345);
    store_le_float(b.data(), 1.0f);
    CHECK(load_le<std::uint32_t>(b.data()) == 0x3f800000u);
}
