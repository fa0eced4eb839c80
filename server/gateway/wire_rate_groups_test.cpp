// Rate groups (wire_rate_groups.hpp) against a fake device that fans each value out to its upstream
// subscribers as MirrorService::deliver does, and a real io_context for the windows' timers.
#include <catch2/catch.hpp>

#include <chrono>
#include <map>
#include <vector>

#include <boost/asio/io_context.hpp>

#include "core/session/elements.hpp"
#include "server/gateway/json_subscriptions.hpp"
#include "server/gateway/rate_ticker.hpp"
#include "server/gateway/wire_rate_groups.hpp"
#include "server/gateway/wire_value_test_support.hpp"

using namespace rr;
using namespace rr::server::gateway;
using namespace std::chrono_literals;

// Named, not anonymous: the TSan preset builds the tests as unity files (json_subscriptions_test.cpp
// has a wire_value of its own).
namespace wire_rate_groups_test {

constexpr auto packet_value = rr::server::gateway::testing::wire_packet_value;
constexpr auto value_of = rr::server::gateway::testing::packet_value_of;

// The device's side: upstream subscriptions of one wire, each called for every value.
struct FakeWire {
    std::map<std::uint64_t, WireRateGroups::OnEntry> subscribers;
    std::vector<WireRateGroups::Done> waiting;  // answered by ready()
    std::uint64_t next = 1, subscribes = 0, unsubscribes = 0, calls = 0;
    bool answer_at_once = true;

    WireRateGroups::Upstream upstream(const std::string& member = "w") {
        WireRateGroups::Upstream up;
        up.source = this;
        up.path = "dev";
        up.member = member;
        up.subscribe = [this](WireRateGroups::OnEntry on_entry, WireRateGroups::Done done) {
            ++subscribes;
            const auto id = next++;
            subscribers[id] = std::move(on_entry);
            if (answer_at_once) done({});
            else waiting.push_back(std::move(done));
            return id;
        };
        up.unsubscribe = [this](std::uint64_t id) {
            ++unsubscribes;
            subscribers.erase(id);
        };
        return up;
    }
    void deliver(const SharedEntryPtr& e) {
        auto subs = subscribers;
        for (auto& [id, f] : subs) {
            ++calls;
            f(e);
        }
    }
};

struct Member {
    std::vector<double> got;
    int done = 0;
    bool ok = false;
    bool closed = false;
    std::uint64_t coalesced = 0;
    std::vector<std::uint64_t> seqs;
    WireRateGroups::OnValue on_value() {
        return [this](const SharedEntryPtr& e, std::uint64_t n, std::uint64_t seq) {
            coalesced += n;
            seqs.push_back(seq);
            if (e->entry().entry_type == MessageEntryType::WireClosed) closed = true;
            else got.push_back(value_of(e));
        };
    }
    WireRateGroups::Done on_done() {
        return [this](Result<void> r) {
            ++done;
            ok = static_cast<bool>(r);
        };
    }
};

// Runs the timers until `until` holds or `limit` (a bound on a hang) passes.
template <class Pred>
void run_until(boost::asio::io_context& io, Pred until, std::chrono::milliseconds limit = 30000ms) {
    const auto end = std::chrono::steady_clock::now() + limit;
    while (!until() && std::chrono::steady_clock::now() < end) {
        io.restart();
        io.run_for(5ms);
    }
}

}  // namespace wire_rate_groups_test
using namespace wire_rate_groups_test;

TEST_CASE("wire rate groups: 100 members of one wire and rate: one upstream subscription, each value offered once, the newest handed to every member once per window") {
    boost::asio::io_context io;
    auto groups = WireRateGroups::create(io.get_executor());
    FakeWire wire;
    std::vector<Member> members(100);
    std::vector<std::uint64_t> ids;
    for (auto& m : members) ids.push_back(groups->join(wire.upstream(), 100ms, m.on_value(), m.on_done()));
    CHECK(wire.subscribes == 1);
    CHECK(groups->groups() == 1);
    for (auto& m : members) CHECK((m.done == 1 && m.ok));

    // A burst of 50 values: at most one hand-out per window of 100 ms it spans, and one more for the
    // value waiting at its end (the windows on rate_window.hpp's grid).
    const RateWindow grid(100ms);
    const auto first_window = grid.window_start(rate_clock_now());
    for (int i = 0; i < 50; ++i) wire.deliver(packet_value(i));
    const auto last_window = grid.window_start(rate_clock_now());
    CHECK(wire.calls == 50);        // the device called one subscriber per value, not 100
    CHECK(groups->offers() == 50);  // and the group took each once
    run_until(io, [&] { return members.back().got.size() >= 1 && members.back().got.back() == 49; });
    const auto max_windows = static_cast<std::size_t>((last_window - first_window) / 100ms) + 2;
    for (auto& m : members) {
        REQUIRE(!m.got.empty());
        CHECK(m.got.front() == 0);   // the window was open: the first value went at once
        CHECK(m.got.back() == 49);   // the last one always arrives, at the next window
        CHECK(m.got.size() <= max_windows);
    }
    CHECK(groups->handed() == members.size() * members.front().got.size());
    // What a member did not see was replaced in the group, and each member is told so.
    CHECK(groups->coalesced() == 50 - members.front().got.size());
    for (auto& m : members) CHECK(m.got.size() + m.coalesced == 50);

    // Every member leaving: the upstream subscription ends with the last.
    for (std::size_t i = 0; i + 1 < ids.size(); ++i) groups->leave(ids[i]);
    CHECK(wire.unsubscribes == 0);
    groups->leave(ids.back());
    CHECK(wire.unsubscribes == 1);
    CHECK(groups->groups() == 0);
    CHECK(wire.subscribers.empty());
}

TEST_CASE("wire rate groups: two rates of one wire are two groups, and a member joining later gets the newest value at once") {
    boost::asio::io_context io;
    auto groups = WireRateGroups::create(io.get_executor());
    FakeWire wire;
    Member slow, fast, late;
    const auto a = groups->join(wire.upstream(), 1000ms, slow.on_value(), slow.on_done());
    const auto b = groups->join(wire.upstream(), 20ms, fast.on_value(), fast.on_done());
    CHECK(wire.subscribes == 2);
    CHECK(groups->groups() == 2);
    const RateWindow slow_grid(1000ms);
    const auto slow_window = slow_grid.window_start(rate_clock_now());
    wire.deliver(packet_value(1));
    wire.deliver(packet_value(2));
    CHECK(groups->offers() == 4);  // one per value and group
    // Each group's window was open: the first value went at once (the second too where a window of
    // the grid began between the two).
    REQUIRE((!slow.got.empty() && !fast.got.empty()));
    CHECK(slow.got.front() == 1);
    CHECK(fast.got.front() == 1);
    run_until(io, [&] { return fast.got.back() == 2; });
    CHECK(fast.got.back() == 2);
    // The newest waits for the slow group's next window, unless one began meanwhile (the grid's 1 s
    // windows start wherever the steady clock's whole seconds fall).
    if (slow_grid.window_start(rate_clock_now()) == slow_window) CHECK(slow.got == std::vector<double>{1});

    groups->join(wire.upstream(), 1000ms, late.on_value(), late.on_done());
    CHECK(wire.subscribes == 2);
    CHECK(late.got == std::vector<double>{2});
    CHECK((late.done == 1 && late.ok));
    groups->leave(a);
    groups->leave(b);
    CHECK(wire.unsubscribes == 1);  // `late` still holds the 1 s group
}

TEST_CASE("wire rate groups: the wire's newest reaching the group's upstream subscription after a newer value (by arrival) is dropped") {
    boost::asio::io_context io;
    auto groups = WireRateGroups::create(io.get_executor());
    FakeWire wire;
    Member m;
    groups->join(wire.upstream(), 20ms, m.on_value(), m.on_done());
    const auto joined_newest = packet_value(1);  // the wire's newest when the group subscribed upstream
    const auto newer = packet_value(2);          // arrived from the device after it, fanned out first
    wire.deliver(newer);
    wire.deliver(joined_newest);
    CHECK(groups->offers() == 2);
    CHECK(groups->coalesced() == 1);
    CHECK(m.got == std::vector<double>{2});  // the first window was open: handed out at once
    io.run_for(30000ms);  // returns once no timer waits (the older value would have armed one)
    CHECK(m.got == std::vector<double>{2});
}

TEST_CASE("wire rate groups: members joining before the wire holds are answered together, and a failure or the device's WireClosed ends the group") {
    boost::asio::io_context io;
    auto groups = WireRateGroups::create(io.get_executor());
    FakeWire wire;
    wire.answer_at_once = false;
    Member m1, m2;
    groups->join(wire.upstream(), 50ms, m1.on_value(), m1.on_done());
    groups->join(wire.upstream(), 50ms, m2.on_value(), m2.on_done());
    REQUIRE(wire.waiting.size() == 1);
    wire.deliver(packet_value(7));  // before the wire holds: kept as the newest
    CHECK(m1.got.empty());
    wire.waiting.front()({});
    CHECK((m1.done == 1 && m1.ok && m2.done == 1 && m2.ok));
    CHECK(m1.got == std::vector<double>{7});
    CHECK(m2.got == std::vector<double>{7});

    MessageEntry closed;
    closed.entry_type = MessageEntryType::WireClosed;
    wire.deliver(std::make_shared<const SharedEntry>(std::move(closed)));
    CHECK((m1.closed && m2.closed));
    CHECK(groups->groups() == 0);

    // A failed subscribe answers every waiting member with the error, and nothing is left.
    wire.waiting.clear();
    Member f;
    const auto id = groups->join(wire.upstream("other"), 50ms, f.on_value(), f.on_done());
    REQUIRE(wire.waiting.size() == 1);
    const auto before = wire.unsubscribes;
    wire.waiting.front()(fail(MessageErrorType::ConnectionError, "away"));
    CHECK((f.done == 1 && !f.ok));
    CHECK(groups->groups() == 0);
    CHECK(wire.unsubscribes == before + 1);  // the failed upstream subscription is undone
    groups->leave(id);                       // already gone: ignored
    CHECK(wire.unsubscribes == before + 1);
}

TEST_CASE("wire rate groups: a value arriving while the group hands its newest to joining members reaches some before the older one: its seq tells, and their socket sends only the newer") {
    boost::asio::io_context io;
    auto groups = WireRateGroups::create(io.get_executor());
    FakeWire wire;
    wire.answer_at_once = false;
    // Two subscriptions of one JSON socket (its registry, as JsonSocketSession::on_wire offers values
    // to it), members of one group; what may go is taken at once, as the socket's flush does.
    JsonSubscriptions subs(8);
    std::map<std::uint64_t, std::vector<double>> sent;
    std::map<std::uint64_t, std::vector<std::uint64_t>> seqs;
    bool second_delivered = false;
    auto socket_member = [&](std::uint64_t sid) -> WireRateGroups::OnValue {
        return [&, sid](const SharedEntryPtr& e, std::uint64_t coalesced, std::uint64_t seq) {
            seqs[sid].push_back(seq);
            if (subs.offer_wire(sid, e, rate_clock_now(), coalesced, seq).send_now) {
                std::vector<WireToSend> out;
                subs.take_wires(out, rate_clock_now());
                for (const auto& w : out) sent[w.subscription].push_back(value_of(w.value));
            }
            // The device's next value arrives while the group is handing value 1 to its members: the
            // first has it, the second not yet.
            if (!second_delivered) {
                second_delivered = true;
                wire.deliver(packet_value(2));
            }
        };
    };
    std::vector<std::uint64_t> sids;
    for (int i = 0; i < 2; ++i) {
        JsonSubscription s;
        s.kind = SubscriptionKind::wire;
        s.target = std::make_shared<const MemberTarget>();
        s.active = true;
        auto added = subs.add(std::move(s));
        REQUIRE(std::holds_alternative<std::uint64_t>(added));
        sids.push_back(std::get<std::uint64_t>(added));
    }
    for (auto sid : sids) groups->join(wire.upstream(), 50ms, socket_member(sid), [](Result<void>) {});
    REQUIRE(wire.waiting.size() == 1);
    wire.deliver(packet_value(1));  // before the wire holds: the newest, for the members when it does
    wire.waiting.front()({});     // the wire holds: value 1 to each member, and value 2 arrives meanwhile

    CHECK(second_delivered);
    CHECK(seqs[sids[0]] == std::vector<std::uint64_t>{1, 2});
    CHECK(seqs[sids[1]] == std::vector<std::uint64_t>{2, 1});  // the older value reached it last
    CHECK(sent[sids[0]] == std::vector<double>{1, 2});
    CHECK(sent[sids[1]] == std::vector<double>{2});  // and its socket did not send it after the newer one
    CHECK(subs.wire_coalesced() == 1);
    CHECK(subs.pending_wires() == 0);
}
