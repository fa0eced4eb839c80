#include <catch2/catch.hpp>

#include <array>
#include <cstdint>
#include <limits>

#include "base/codec/byte_reader.hpp"

using namespace rr;

namespace {
template <std::size_t N>
std::array<std::byte, N> bytes_of(const std::uint8_t (&in)[N]) {
    std::array<std::byte, N> out{};
    for (std::size_t i = 0; i < N; ++i) out[i] = static_cast<std::byte>(in[i]);
    return out;
}
}  // namespace

TEST_CASE("codec: ByteReader reads little-endian integers in order") {
    auto b = bytes_of({0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0xf7, 0xfe, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08});
    ByteReader r(b);
    CHECK(*r.read_u8() == 0x01);
    CHECK(*r.read_u16() == 0x0302);
    CHECK(*r.read_u32() == 0xf7060504u);
    CHECK(*r.read_i8() == -2);
    CHECK(*r.read_u64() == 0x0807060504030201ull);
    CHECK(r.at_end());
    CHECK(r.position() == b.size());
}

TEST_CASE("codec: ByteReader never reads past the end and keeps its cursor on failure") {
    auto b = bytes_of({0xaa, 0xbb, 0xcc});
    ByteReader r(b);
    REQUIRE(*r.read_u8() == 0xaa);
    auto big = r.read_u32();
    REQUIRE_FALSE(big);
    CHECK(big.error().type == MessageErrorType::ProtocolError);
    CHECK(r.position() == 1);
    CHECK_FALSE(r.take(3));
    CHECK(r.position() == 1);
    CHECK_FALSE(r.skip(3));
    auto s = r.take(2);
    REQUIRE(s);
    CHECK(s->size() == 2);
    CHECK((*s)[1] == std::byte{0xcc});
    CHECK(r.at_end());
    CHECK(r.take(0));
    CHECK_FALSE(r.read_u8());
}

TEST_CASE("codec: ByteReader take_array checks count x size for overflow") {
    auto b = bytes_of({1, 2, 3, 4, 5, 6, 7, 8});
    ByteReader r(b);
    CHECK(r.take_array(2, 4));
    ByteReader r2(b);
    auto huge = r2.take_array(std::numeric_limits<std::size_t>::max() / 2 + 1, 2);  // wraps to 0 if unchecked
    REQUIRE_FALSE(huge);
    CHECK(huge.error().type == MessageErrorType::ProtocolError);
    CHECK(r2.position() == 0);
    CHECK_FALSE(r2.take_array(3, 4));
    CHECK(r2.take_array(1000, 0));  // zero-size items take nothing
}

TEST_CASE("codec: ByteReader sub_reader bounds nested reads") {
    auto b = bytes_of({3, 'a', 'b', 'c', 9});
    ByteReader r(b);
    auto n = r.read_u8();
    auto sub = r.sub_reader(*n);
    REQUIRE(sub);
    CHECK(*sub->read_string(3) == "abc");
    CHECK_FALSE(sub->read_u8());
    CHECK(*r.read_u8() == 9);
    CHECK_FALSE(r.sub_reader(1));
}
