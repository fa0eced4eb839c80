// TokenBucket and AddressLimiter, with time moved by hand.
#include <catch2/catch.hpp>

#include "server/common/address_limiter.hpp"
#include "server/common/token_bucket.hpp"

using namespace rr::server;
using namespace std::chrono_literals;
using T = TokenBucket::Clock::time_point;

TEST_CASE("token bucket: a full bucket lets a burst through, then asks to wait for the refill") {
    const T t0{};
    TokenBucket b(100, 10, t0);  // 100 tokens/s, burst 10
    for (int i = 0; i < 10; ++i) CHECK(b.take(1, t0) == 0ns);
    // the 11th token is a debt of 1 at 100/s: 10 ms
    CHECK(b.take(1, t0) == 10ms);
    CHECK(b.wait_time(t0 + 5ms) == 5ms);
    CHECK(b.wait_time(t0 + 10ms) == 0ns);
    // refill never goes above the burst
    CHECK(b.level(t0 + 10s) == Approx(10.0));
}

TEST_CASE("token bucket: the average rate over time is the configured one, whatever the message sizes") {
    T t{};
    TokenBucket b(1000, 1000, t);  // 1000 bytes/s
    std::uint64_t sent = 0;
    // a peer sends 300-byte messages as fast as the bucket lets it, for 10 s of virtual time
    const T end = t + 10s;
    while (t < end) {
        sent += 300;
        t += b.take(300, t);
    }
    // 10 s at 1000/s plus the initial burst; at most one message beyond
    CHECK(sent >= 10000);
    CHECK(sent <= 11000 + 300);
}

TEST_CASE("token bucket: a message bigger than the burst passes, and its size is paid back by waiting") {
    const T t0{};
    TokenBucket b(1000, 100, t0);
    CHECK(b.take(5100, t0) == 5s);  // 5000 tokens of debt at 1000/s
    CHECK(b.level(t0 + 2s) == Approx(-3000.0));
    CHECK(b.wait_time(t0 + 5s) == 0ns);
}

TEST_CASE("token bucket: rate 0 is unlimited, burst 0 means one second of rate, time going back is ignored") {
    const T t0{};
    TokenBucket none(0, 0, t0);
    CHECK(none.unlimited());
    CHECK(none.take(1u << 30, t0) == 0ns);

    TokenBucket b(50, 0, t0 + 1s);
    CHECK(b.burst() == 50);
    CHECK(b.take(50, t0 + 1s) == 0ns);
    CHECK(b.take(5, t0) == 100ms);  // an earlier time counts as the last one: no refill
}

TEST_CASE("address limiter: the third connection from one address is refused, another address is not") {
    auto l = AddressLimiter::create(2);
    auto a1 = l->acquire("127.0.0.1");
    auto a2 = l->acquire("127.0.0.1");
    REQUIRE(a1);
    REQUIRE(a2);
    CHECK_FALSE(l->acquire("127.0.0.1"));
    CHECK(l->refused() == 1);
    auto b1 = l->acquire("127.0.0.2");
    CHECK(b1);
    CHECK(l->count("127.0.0.1") == 2);
    CHECK(l->addresses() == 2);
    a1.reset();  // a connection closes: its slot comes back
    CHECK(l->count("127.0.0.1") == 1);
    CHECK(l->acquire("127.0.0.1"));  // (released again at once: the temporary slot dies)
    CHECK(l->count("127.0.0.1") == 1);
    a2.reset();
    b1.reset();
    CHECK(l->addresses() == 0);  // no entry stays behind for an address with nothing open
}

TEST_CASE("address limiter: 0 is unlimited, and a slot outliving its limiter is harmless") {
    auto l = AddressLimiter::create(0);
    std::vector<std::shared_ptr<AddressLimiter::Slot>> slots;
    for (int i = 0; i < 100; ++i) slots.push_back(l->acquire("::1"));
    for (auto& s : slots) CHECK(s);
    CHECK(l->count("::1") == 100);
    l.reset();
    slots.clear();  // the slots release into a limiter that is gone: nothing happens
}
