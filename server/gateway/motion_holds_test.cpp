// MotionHolds with time passed in: one holder at a time, refusals naming it, the hold's end by each
// of its causes (the hold-to-run timeout, the motion's end, a stop, the owner's departure, a silent
// stream), and which departures need the device stopped.
#include <catch2/catch.hpp>

#include "server/gateway/motion_holds.hpp"

using namespace rr;
using namespace rr::server::gateway;
using namespace std::chrono_literals;

namespace {

MotionClient client(std::string key, std::string user, std::string description) {
    MotionClient c;
    c.key = std::move(key);
    c.user = std::move(user);
    c.description = std::move(description);
    return c;
}

const MotionHolds::Time t0{std::chrono::seconds(1000)};

}  // namespace

TEST_CASE("motion holds: a second client is refused with the holder's name while a hold-to-run call lasts", "[motion]") {
    MotionHolds h(500ms);
    auto alice = client("ws:1", "alice", "JSON WebSocket from 10.0.0.5");
    auto bob = client("rr:7", "bob", "RR session from 10.0.0.6:40112");
    REQUIRE(h.take(alice, t0, "10:00:01.000Z", "arm"));
    h.timed(t0 + 150ms);
    auto refused = h.take(bob, t0 + 100ms, "x", "arm");
    REQUIRE_FALSE(refused);
    CHECK(refused.error().type == MessageErrorType::ObjectLockedError);
    CHECK(refused.error().message.find("motion of arm is held by alice (JSON WebSocket from 10.0.0.5) since 10:00:01.000Z") == 0);
    // The holder renews; the other is still refused.
    REQUIRE(h.take(alice, t0 + 120ms, "y", "arm"));
    h.timed(t0 + 270ms);
    CHECK_FALSE(h.take(bob, t0 + 200ms, "x", "arm"));
    // After the last call's timeout the hold is free.
    REQUIRE(h.holder(t0 + 269ms));
    CHECK_FALSE(h.holder(t0 + 270ms));
    REQUIRE(h.take(bob, t0 + 271ms, "10:00:01.271Z", "arm"));
    CHECK(h.holder(t0 + 271ms) == nullptr);  // took it, nothing running yet
    h.timed(t0 + 400ms);
    REQUIRE(h.holder(t0 + 300ms));
    CHECK(h.holder(t0 + 300ms)->key == "rr:7");
}

TEST_CASE("motion holds: a motion without a timeout holds until it ends, a stop, or its owner's departure", "[motion]") {
    MotionHolds h(500ms);
    auto alice = client("rr:1", "", "RR session from 10.0.0.5:1");
    auto bob = client("rr:2", "bob", "RR session from 10.0.0.6:2");
    REQUIRE(h.take(alice, t0, "s", "arm"));
    const auto token = h.begin_untimed("rr:1", "jog_freespace");
    CHECK(h.probed() != nullptr);
    auto refused = h.take(bob, t0 + 10s, "x", "arm");
    REQUIRE_FALSE(refused);
    CHECK(refused.error().message.find("held by RR session from 10.0.0.5:1 since s") != std::string::npos);  // anonymous: no user
    h.end_untimed(token);
    CHECK(h.probed() == nullptr);
    CHECK_FALSE(h.holder(t0 + 10s));
    REQUIRE(h.take(bob, t0 + 10s, "x", "arm"));

    // A stop by anyone ends the hold.
    h.begin_untimed("rr:2", "execute_trajectory");
    CHECK_FALSE(h.take(alice, t0 + 11s, "x", "arm"));
    h.stopped();
    REQUIRE(h.take(alice, t0 + 11s, "x", "arm"));

    // The owner's departure ends its motions and asks for a stop; a departure of someone else asks none.
    const auto t2 = h.begin_untimed("rr:1", "jog_freespace");
    auto other = h.gone("rr:9", t0 + 12s);
    CHECK_FALSE(other.stop);
    CHECK(h.has_token(t2));
    auto g = h.gone("rr:1", t0 + 12s);
    CHECK(g.stop);
    REQUIRE(g.tokens.size() == 1);
    CHECK(g.tokens[0] == t2);
    CHECK_FALSE(h.holder(t0 + 12s));
}

TEST_CASE("motion holds: an HTTP request's connection owns its motion, the user's address holds", "[motion]") {
    MotionHolds h(500ms);
    auto first = client("http:alice@10.0.0.5", "alice", "HTTP requests from 10.0.0.5");
    first.owner = "http-request:1";
    auto second = first;
    second.owner = "http-request:2";
    REQUIRE(h.take(first, t0, "s", "arm"));
    h.timed(t0 + 500ms);
    // The same user from the same address renews the hold with a new request.
    REQUIRE(h.take(second, t0 + 100ms, "s", "arm"));
    const auto token = h.begin_untimed(second.owner_key(), "jog_freespace");
    // The first request's connection closing ends nothing of the second's.
    CHECK_FALSE(h.gone("http-request:1", t0 + 200ms).stop);
    CHECK(h.has_token(token));
    auto g = h.gone("http-request:2", t0 + 300ms);
    CHECK(g.stop);
}

TEST_CASE("motion holds: a command stream holds while its packets come, and its silence is reported once", "[motion]") {
    MotionHolds h(500ms);
    auto streamer = client("rr:3", "carol", "RR session from 10.0.0.7:3");
    auto other = client("ws:4", "dave", "JSON WebSocket from 10.0.0.8");
    REQUIRE(h.take(streamer, t0, "s", "arm"));
    h.stream_packet("position_command", t0);
    CHECK(h.probed());
    for (int i = 1; i <= 10; ++i) {
        REQUIRE(h.take(streamer, t0 + i * 100ms, "s", "arm"));
        h.stream_packet("position_command", t0 + i * 100ms);
        CHECK(h.expire(t0 + i * 100ms).empty());
    }
    CHECK_FALSE(h.take(other, t0 + 1200ms, "x", "arm"));
    REQUIRE(h.next_deadline());
    CHECK(*h.next_deadline() == t0 + 1500ms);
    CHECK(h.expire(t0 + 1499ms).empty());
    auto silent = h.expire(t0 + 1500ms);
    REQUIRE(silent.size() == 1);
    CHECK(silent[0] == "position_command");
    CHECK(h.expire(t0 + 1600ms).empty());  // reported once
    CHECK_FALSE(h.next_deadline());
    REQUIRE(h.take(other, t0 + 1600ms, "x", "arm"));
}

TEST_CASE("motion holds: the streamer's departure while streaming asks for a stop", "[motion]") {
    MotionHolds h(500ms);
    auto streamer = client("rr:3", "", "RR session");
    REQUIRE(h.take(streamer, t0, "s", "arm"));
    h.stream_packet("velocity_command", t0);
    auto g = h.gone("rr:3", t0 + 100ms);
    CHECK(g.stop);
    CHECK(g.tokens.empty());
    // Its connection closing just as the stream goes quiet (before the timer reported it): still a stop.
    REQUIRE(h.take(streamer, t0 + 200ms, "s", "arm"));
    h.stream_packet("velocity_command", t0 + 200ms);
    CHECK(h.gone("rr:3", t0 + 800ms).stop);
    // A stream that had gone silent already needs no second stop when its sender leaves.
    REQUIRE(h.take(streamer, t0 + 1s, "s", "arm"));
    h.stream_packet("velocity_command", t0 + 1s);
    h.timed(t0 + 3s);
    (void)h.expire(t0 + 2s);
    CHECK_FALSE(h.gone("rr:3", t0 + 2100ms).stop);
}
