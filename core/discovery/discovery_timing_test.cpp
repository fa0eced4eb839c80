#include <catch2/catch.hpp>

#include <vector>

#include "core/discovery/discovery_timing.hpp"

using namespace rr::discovery;
using namespace std::chrono_literals;

namespace {
const MonoTime t0 = MonoTime{} + 1000s;
}

TEST_CASE("discovery timing: announces 500 ms after start, then every 55 s") {
    AnnounceSchedule a;
    CHECK_FALSE(a.due(t0));
    a.start(t0);
    CHECK(a.next_deadline() == t0 + 500ms);
    CHECK_FALSE(a.due(t0 + 499ms));
    CHECK(a.due(t0 + 500ms));
    CHECK(a.next_deadline() == t0 + 500ms + 55s);
    CHECK_FALSE(a.due(t0 + 30s));
    CHECK(a.due(t0 + 56s));
    CHECK(a.next_deadline() == t0 + 111s);
}

TEST_CASE("discovery timing: a request or a nonce change pulls the announce in to 500 ms") {
    AnnounceSchedule a;
    a.start(t0);
    REQUIRE(a.due(t0 + 500ms));
    a.announce_soon(t0 + 10s);
    CHECK(a.next_deadline() == t0 + 10500ms);
    a.announce_soon(t0 + 10200ms);  // never later than planned
    CHECK(a.next_deadline() == t0 + 10500ms);
    CHECK(a.due(t0 + 10500ms));
    CHECK(a.next_deadline() == t0 + 65500ms);
    a.stop();
    a.announce_soon(t0 + 11s);
    CHECK_FALSE(a.running());
    // Periods below 500 ms are raised to 500 ms.
    a.start(t0, 10ms);
    CHECK(a.period() == 500ms);
}

TEST_CASE("discovery timing: requests go out in rounds of three") {
    RequestSchedule r;
    r.trigger(t0, 0);
    CHECK(r.next_deadline() == t0 + 250ms);
    std::vector<MonoTime> sent;
    MonoTime now = t0;
    for (int i = 0; i < 10 && r.next_deadline(); ++i) {
        now = *r.next_deadline();
        if (r.due(now, 600)) sent.push_back(now);  // 600 % 601 → 900 + 600 = 1500 ms
    }
    REQUIRE(sent.size() == 3);
    CHECK(sent[0] == t0 + 250ms);
    CHECK(sent[1] == t0 + 1750ms);
    CHECK(sent[2] == t0 + 3250ms);
    CHECK_FALSE(r.next_deadline());
}

TEST_CASE("discovery timing: a trigger near the end of a round adds a round 5 s later") {
    RequestSchedule r;
    r.trigger(t0, 750);  // 250 + 750 → first at 1000 ms
    CHECK(r.next_deadline() == t0 + 1000ms);
    REQUIRE(r.due(t0 + 1000ms, 0));
    CHECK(r.next_deadline() == t0 + 1900ms);
    REQUIRE(r.due(t0 + 1900ms, 0));
    r.trigger(t0 + 2500ms, 0);  // within the round: no new round yet
    CHECK(r.next_deadline() == t0 + 2800ms);
    REQUIRE(r.due(t0 + 2800ms, 0));
    CHECK(r.next_deadline() == t0 + 7800ms);
    int more = 0;
    MonoTime now = t0 + 7800ms;
    while (r.next_deadline()) {
        now = *r.next_deadline();
        more += r.due(now, 0) ? 1 : 0;
    }
    CHECK(more == 3);
}
