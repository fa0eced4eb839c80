// RrMessageCounter and ReadThrottle, with time moved by hand.
#include <catch2/catch.hpp>

#include <vector>

#include "server/common/read_throttle.hpp"

using namespace rr::server;
using namespace std::chrono_literals;
using T = ReadThrottle::Clock::time_point;

namespace {

// An RR-framed message of `size` bytes in total (`RRAC`, uint32 LE size, then filler).
std::vector<std::byte> rr_message(std::uint32_t size) {
    std::vector<std::byte> m(size, std::byte{0x5a});
    const char magic[] = "RRAC";
    for (int i = 0; i < 4; ++i) m[i] = static_cast<std::byte>(magic[i]);
    for (int i = 0; i < 4; ++i) m[4 + i] = static_cast<std::byte>((size >> (8 * i)) & 0xff);
    return m;
}

std::vector<std::byte> stream_of(int count, std::uint32_t size) {
    std::vector<std::byte> s;
    for (int i = 0; i < count; ++i) {
        auto m = rr_message(size);
        s.insert(s.end(), m.begin(), m.end());
    }
    return s;
}

}  // namespace

TEST_CASE("RR message counter: messages counted once, whatever the read boundaries") {
    const auto s = stream_of(10, 100);
    for (std::size_t chunk : {std::size_t{1}, std::size_t{3}, std::size_t{7}, std::size_t{8}, std::size_t{64},
                              std::size_t{100}, std::size_t{1000}}) {
        RrMessageCounter c;
        std::uint64_t total = 0;
        for (std::size_t off = 0; off < s.size(); off += chunk)
            total += c.feed(std::span<const std::byte>(s).subspan(off, std::min(chunk, s.size() - off)));
        INFO("chunk " << chunk);
        CHECK(total == 10);
    }
    // A message is counted when its 8-byte header is complete, not before.
    RrMessageCounter c;
    auto m = rr_message(50);
    CHECK(c.feed(std::span<const std::byte>(m).first(7)) == 0);
    CHECK(c.feed(std::span<const std::byte>(m).subspan(7, 1)) == 1);
    CHECK(c.feed(std::span<const std::byte>(m).subspan(8)) == 0);
    // A size below the header's own 8 bytes is treated as an 8-byte message (no underflow).
    auto tiny = rr_message(8);
    tiny[4] = std::byte{2};
    auto next = rr_message(20);
    tiny.insert(tiny.end(), next.begin(), next.end());
    CHECK(c.feed(tiny) == 2);
}

TEST_CASE("read throttle: unlimited rates never pause") {
    const T t0{};
    ReadThrottle t(ReadRates{}, t0);
    const auto s = stream_of(1000, 1000);
    CHECK(t.charge(s, t0) == 0ns);
}

TEST_CASE("read throttle: messages per second, with a burst of burst_s seconds") {
    const T t0{};
    ReadThrottle t(ReadRates{10, 0, 2}, t0);  // 10 messages/s, 2 s of burst = 20 messages
    const auto one = rr_message(64);
    for (int i = 0; i < 20; ++i) CHECK(t.charge(one, t0) == 0ns);
    CHECK(t.charge(one, t0) == 100ms);  // the 21st is a debt of one message at 10/s
    // Once the debt is paid back, each further message costs 100 ms; quiet time saves tokens up again.
    CHECK(t.charge(one, t0 + 100ms) == 100ms);
    CHECK(t.charge(one, t0 + 300ms) == 0ns);
}

TEST_CASE("read throttle: bytes per second, and the average over a flood stays at the rate") {
    const T t0{};
    ReadThrottle t(ReadRates{0, 10000, 1}, t0);  // 10 kB/s, burst 10 kB
    const auto chunk = stream_of(1, 5000);
    CHECK(t.charge(chunk, t0) == 0ns);
    CHECK(t.charge(chunk, t0) == 0ns);  // exactly the burst: level 0, no wait
    CHECK(t.charge(chunk, t0) == 500ms);
    // A reader that honours every pause: 100 reads of 5 kB take (100*5000 - 10000) / 10000 s.
    ReadThrottle f(ReadRates{0, 10000, 1}, t0);
    T now = t0;
    for (int i = 0; i < 100; ++i) now += f.charge(chunk, now);
    CHECK(now - t0 >= 49s);
    CHECK(now - t0 < 49s + 1ms);  // rounding up to whole nanoseconds, at most 1 ns per read
}

TEST_CASE("read throttle: the stricter of the two rates sets the pause") {
    const T t0{};
    ReadThrottle t(ReadRates{1000, 1024, 1}, t0);  // many small messages allowed, few bytes
    const auto s = stream_of(4, 1024);              // 4 messages, 4 KiB
    CHECK(t.charge(s, t0) == 3s);                   // bytes: 3 KiB of debt at 1 KiB/s; messages: none
    ReadThrottle m(ReadRates{2, 1u << 20, 1}, t0);  // few messages, many bytes
    CHECK(m.charge(stream_of(4, 16), t0) == 1s);    // 2 messages of debt at 2/s
}

TEST_CASE("read throttle: whole messages of other protocols (HTTP requests, JSON WebSocket messages)") {
    const T t0{};
    ReadThrottle t(ReadRates{5, 1000, 1}, t0);  // 5 messages/s, 1000 bytes/s, 1 s of burst
    for (int i = 0; i < 5; ++i) CHECK(t.charge_message(100, t0) == 0ns);
    CHECK(t.charge_message(100, t0) == 200ms);   // the sixth message: one message of debt at 5/s
    CHECK(t.charge_message(2000, t0) == 1600ms);  // bytes: 400 left of the burst, 2000 taken, at 1000/s
    ReadThrottle off(ReadRates{}, t0);
    for (int i = 0; i < 1000; ++i) REQUIRE(off.charge_message(1u << 20, t0) == 0ns);
}
