// The LFSR against outputs of the official implementation (robotraconteur/robotraconteur,
// test/python/RobotRaconteurTest/lfsr.py at commit 018ccf2, run by hand): a wrong tap, shift or hash
// step changes every one of these numbers. test/testsvc/lfsr_official_compare.py compares many more
// sequences when a checkout of the official repository is at hand.
#include <catch2/catch.hpp>

#include <bit>
#include <vector>

#include "test/testsvc/lfsr.hpp"

using rr::testsvc::Lfsr;

TEST_CASE("testsvc lfsr: seeded key, then every value kind, as the official generator draws them") {
    Lfsr g(35913226, "Hello World!");
    CHECK(g.state() == 2211316493u);
    std::vector<std::uint32_t> u32;
    for (int i = 0; i < 4; ++i) u32.push_back(g.next_uint32());
    CHECK(u32 == std::vector<std::uint32_t>{1105658246u, 552829123u, 2423898209u, 3359432752u});
    std::vector<int> i8;
    for (int i = 0; i < 4; ++i) i8.push_back(g.next_int8());
    CHECK(i8 == std::vector<int>{24, 12, 6, 3});
    std::vector<int> i16;
    for (int i = 0; i < 3; ++i) i16.push_back(g.next_int16());
    CHECK(i16 == std::vector<int>{-6399, -3200, 31168});
    CHECK(std::bit_cast<std::uint64_t>(g.next_double()) == 0xd8c83ce0ec641e70ull);
    CHECK(std::bit_cast<std::uint64_t>(g.next_double()) == 0x76320f38bb19079cull);
    CHECK(std::bit_cast<std::uint64_t>(g.next_double()) == 0xdd8c83ce6ec641e7ull);
    CHECK(g.next_uint64() == 3991069925441638521ull);
    CHECK(g.next_uint64() == 14832825536642573342ull);
    CHECK(g.next_int64() == -903479633193002745ll);
    CHECK(g.next_int64() == -4837555926725638591ll);
    CHECK(std::bit_cast<std::uint32_t>(g.next_float()) == 0xef376320u);
    CHECK(std::bit_cast<std::uint32_t>(g.next_float()) == 0x779bb190u);
    CHECK(g.next_string(8) == "*%UmIdE2");
    CHECK(g.next_len(32) == 24);
    CHECK(g.next_len(5) == 1);
    CHECK(g.next_dist(1, 4) == 3);
    std::vector<bool> b;
    for (int i = 0; i < 4; ++i) b.push_back(g.next_bool());
    CHECK(b == std::vector<bool>{true, true, false, true});
}

TEST_CASE("testsvc lfsr: initial states of other seeds and keys") {
    CHECK(Lfsr(1234, "multidimarray_test_double").state() == 877181456u);
    CHECK(Lfsr(0, "").state() == 0u);  // the all-zero register stays at zero
    CHECK(Lfsr(4294967295u, "x").state() == 1625878727u);
    CHECK(Lfsr::step(0) == 0u);
    CHECK(Lfsr::step(1) == 0x80000000u);  // bit 0 feeds back into bit 31
    CHECK(Lfsr::step(2) == 0x80000001u);  // bit 1 too
    CHECK(Lfsr::step(0x80000000u) == 0xC0000000u);  // and bit 31
}
