// A subscription's maximum rate (rate_window.hpp) and what the registry does with it
// (json_subscriptions.hpp), with the time injected: no clock, no socket.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

#include "core/session/elements.hpp"
#include "server/gateway/json_subscriptions.hpp"
#include "server/gateway/rate_window.hpp"
#include "server/gateway/wire_value_test_support.hpp"

using namespace rr;
using namespace rr::server::gateway;
using namespace std::chrono_literals;

namespace {

constexpr auto wire_value = rr::server::gateway::testing::wire_packet_value;
double value_of(const SharedEntryPtr& e) { return rr::server::gateway::testing::packet_value_of(e); }
MessageElement packet(double v) { return make_scalar_element<double>("packet", v); }
double value_of(const MessageElement& e) {
    double v = -1;
    REQUIRE(read_scalar(e, v));
    return v;
}

std::uint64_t add_rate_limited(JsonSubscriptions& subs, SubscriptionKind kind, RateClock period, std::size_t queue_length = 1) {
    JsonSubscription s;
    s.kind = kind;
    s.target = std::make_shared<const MemberTarget>();
    s.rate = RateWindow(period);
    s.queue_length = queue_length;
    auto added = subs.add(std::move(s));
    REQUIRE(std::holds_alternative<std::uint64_t>(added));
    const auto sid = std::get<std::uint64_t>(added);
    subs.find(sid)->active = true;
    return sid;
}

}  // namespace

TEST_CASE("rate window: max_rate_hz from 0.01 to 1000, and zero, negative, NaN, infinite and larger refused") {
    CHECK(rate_period(10).period == 100ms);
    CHECK(rate_period(1000).period == 1ms);
    CHECK(rate_period(0.01).period == 100s);
    CHECK(rate_period(3).period == RateClock(333'333'333));
    for (double bad : {0.0, -1.0, 1000.5, 0.005, std::nan(""), std::numeric_limits<double>::infinity(), -0.0}) {
        INFO(bad);
        const auto r = rate_period(bad);
        CHECK(r.period == RateClock(0));
        CHECK(r.error == "\"max_rate_hz\" must be a number from 0.01 to 1000");
    }
}

TEST_CASE("rate window: at most one value per window, windows on one grid") {
    RateWindow unlimited;
    CHECK(unlimited.open(0ns));
    unlimited.sent(5ns);
    CHECK(unlimited.open(5ns));

    RateWindow w(100ms);
    CHECK(w.open(1'234ms));  // nothing sent yet
    w.sent(1'234ms);         // window [1200, 1300)
    CHECK_FALSE(w.open(1'250ms));
    CHECK_FALSE(w.open(1'299ms));
    CHECK(w.next_open() == 1'300ms);
    CHECK(w.open(1'300ms));
    w.sent(1'307ms);  // a timer late by 7 ms still sends in window [1300, 1400): the rate holds
    CHECK(w.next_open() == 1'400ms);

    // Two windows of the same period opened at different times share the grid (the same instants).
    RateWindow a(100ms), b(100ms);
    a.sent(10ms);
    b.sent(95ms);
    CHECK(a.next_open() == b.next_open());
}

TEST_CASE("rate window: a fast source through a 10 Hz wire subscription: fewer values, in order, the last one delivered") {
    JsonSubscriptions subs(8);
    const auto sid = add_rate_limited(subs, SubscriptionKind::wire, 100ms);
    std::vector<double> sent;
    std::vector<WireToSend> batch;
    std::size_t waits = 0;
    // A 1 kHz source for one second; the gateway's socket sends what may go, and wakes at each window
    // start it asked for (as RateTicker does).
    RateClock wake{-1};
    for (int i = 0; i < 1000; ++i) {
        const RateClock now = 5'000ms + RateClock(i * 1'000'000);
        if (wake.count() >= 0 && now >= wake) {  // the timer fires at the window's start
            subs.take_wires(batch, wake);
            for (auto& w : batch) sent.push_back(value_of(w.value));
            wake = RateClock{-1};
        }
        const Offered o = subs.offer_wire(sid, wire_value(i), now);
        if (o.send_now) {
            subs.take_wires(batch, now);
            for (auto& w : batch) sent.push_back(value_of(w.value));
        } else {
            REQUIRE(o.wait == 100ms);
            ++waits;
            if (wake.count() < 0) wake = RateWindow(o.wait).window_start(now) + o.wait;
        }
    }
    // The source stopped: its last value goes at the next window's start.
    REQUIRE(wake.count() >= 0);
    subs.take_wires(batch, wake);
    for (auto& w : batch) sent.push_back(value_of(w.value));

    CHECK(sent.size() == 11);  // one per 100 ms window of [5.0 s, 6.0 s], plus the trailing one at 6.0 s
    CHECK(sent.front() == 0);
    CHECK(sent.back() == 999);
    CHECK(std::is_sorted(sent.begin(), sent.end()));
    CHECK(std::adjacent_find(sent.begin(), sent.end()) == sent.end());
    CHECK(waits == 999);  // every value but the first came inside a window that had its value
    CHECK(subs.wire_coalesced() == 1000 - 11);
    CHECK(subs.pending_wires() == 0);
}

TEST_CASE("rate window: a waiting wire value is not taken before its window, and says which rate to wake at") {
    JsonSubscriptions subs(8);
    const auto slow = add_rate_limited(subs, SubscriptionKind::wire, 500ms);
    const auto fast = add_rate_limited(subs, SubscriptionKind::wire, 10ms);
    CHECK(subs.offer_wire(slow, wire_value(1), 1'000ms).send_now);
    CHECK(subs.offer_wire(fast, wire_value(1), 1'000ms).send_now);
    std::vector<WireToSend> batch;
    subs.take_wires(batch, 1'000ms);
    CHECK(batch.size() == 2);

    CHECK(subs.offer_wire(slow, wire_value(2), 1'001ms).wait == 500ms);
    CHECK(subs.offer_wire(fast, wire_value(2), 1'001ms).wait == 10ms);
    std::vector<RateClock> waiting;
    subs.rate_waiting(1'001ms, waiting);
    CHECK(waiting == std::vector<RateClock>{500ms, 10ms});
    CHECK_FALSE(subs.wires_waiting(1'005ms));

    subs.take_wires(batch, 1'010ms);  // the fast one's window
    REQUIRE(batch.size() == 1);
    CHECK(batch[0].subscription == fast);
    waiting.clear();
    subs.rate_waiting(1'010ms, waiting);
    CHECK(waiting == std::vector<RateClock>{500ms});
    subs.take_wires(batch, 1'500ms);
    REQUIRE(batch.size() == 1);
    CHECK(batch[0].subscription == slow);
    CHECK(value_of(batch[0].value) == 2);
}

TEST_CASE("rate window: a rate-limited pipe keeps the newest queue_length packets, drops older ones and counts them") {
    JsonSubscriptions subs(8);
    const auto sid = add_rate_limited(subs, SubscriptionKind::pipe, 100ms, 3);
    std::optional<PipeToSend> out;

    // The first packet goes at once (its window is open); 10 more in the same window wait.
    CHECK(subs.offer_pipe(sid, packet(0), false, 2'000ms, out).send_now);
    REQUIRE(out);
    CHECK(value_of(out->packet) == 0);
    CHECK(out->ticket.dropped == 0);
    for (int i = 1; i <= 10; ++i) {
        const Offered o = subs.offer_pipe(sid, packet(i), false, 2'000ms + RateClock(i * 1'000'000), out);
        CHECK_FALSE(o.send_now);
        CHECK(o.wait == 100ms);
        CHECK_FALSE(out);
    }
    CHECK(subs.push_drops() == 7);  // 1..7 dropped: 8, 9, 10 wait

    // One per window, oldest first; the first carries the drops.
    std::vector<PipeToSend> taken;
    std::vector<RateClock> waiting;
    std::vector<double> got;
    std::uint64_t dropped = 0;
    for (RateClock t = 2'100ms; t <= 2'500ms; t += 100ms) {
        waiting.clear();
        subs.take_pipe_packets(taken, false, t, waiting);
        for (auto& p : taken) {
            got.push_back(value_of(p.packet));
            dropped += p.ticket.dropped;
        }
        if (got.size() < 3) CHECK(waiting == std::vector<RateClock>{100ms});
    }
    CHECK(got == std::vector<double>{8, 9, 10});
    CHECK(dropped == 7);
    CHECK(waiting.empty());

    // While the client is congested packets stay queued (the oldest still dropped beyond the length).
    CHECK_FALSE(subs.offer_pipe(sid, packet(11), true, 3'000ms, out).send_now);
    waiting.clear();
    subs.take_pipe_packets(taken, true, 3'100ms, waiting);
    CHECK(taken.empty());
    CHECK(waiting == std::vector<RateClock>{100ms});
    subs.take_pipe_packets(taken, false, 3'100ms, waiting);
    REQUIRE(taken.size() == 1);
    CHECK(value_of(taken[0].packet) == 11);
}

TEST_CASE("rate window: a rate-limited pipe's queue is bounded by bytes too, one packet always kept") {
    JsonSubscriptions subs(8);
    const auto sid = add_rate_limited(subs, SubscriptionKind::pipe, 100ms, 64);
    subs.find(sid)->queue_bytes_limit = 20;  // two doubles' payload (8 bytes each) fit, not three
    std::optional<PipeToSend> out;
    CHECK(subs.offer_pipe(sid, packet(0), false, 1'000ms, out).send_now);
    for (int i = 1; i <= 5; ++i) subs.offer_pipe(sid, packet(i), false, 1'001ms, out);
    CHECK(subs.find(sid)->pipe_queue.size() == 2);
    CHECK(subs.push_drops() == 3);
}
