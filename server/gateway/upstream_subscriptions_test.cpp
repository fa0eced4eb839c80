// UpstreamSubscriptions without sockets: one upstream wire connection per member whatever the number of
// subscribers, waiters answered by the upstream connect, the newest value for late subscribers, and
// the disconnects asked for when the last subscriber of either front end leaves.
#include <catch2/catch.hpp>

#include "server/gateway/upstream_subscriptions.hpp"
#include "server/node/server_connection.hpp"

using namespace rr;
using namespace rr::server;
using namespace rr::server::gateway;

namespace {

using SubKey = UpstreamSubscriptions::MemberKey;

struct SubscriberSessions {
    std::vector<std::shared_ptr<ServerSession>> held;
    SessionRef make(std::uint32_t endpoint) {
        held.push_back(std::make_shared<ServerSession>(endpoint, endpoint + 100, nullptr, std::weak_ptr<PumpHandle>(),
                                                       std::weak_ptr<ServerConnection>(), 1u << 20));
        return SessionRef(held.back());
    }
};

SharedEntryPtr wire_value_entry(const SubKey& key, std::int32_t value) {
    MessageEntry e;
    e.entry_type = MessageEntryType::WirePacket;
    e.service_path = key.first;
    e.member_name = key.second;
    e.request_id = static_cast<std::uint32_t>(value);  // a marker to tell values apart
    return std::make_shared<const SharedEntry>(std::move(e));
}

struct ReadyOutcomes {
    std::vector<Result<void>> got;
    UpstreamSubscriptions::Ready ready() {
        return [this](Result<void> r) { got.push_back(std::move(r)); };
    }
};

void answer_all(std::vector<UpstreamSubscriptions::Ready> waiting, const Result<void>& outcome) {
    for (auto& w : waiting)
        if (w) w(outcome);
}

}  // namespace

TEST_CASE("upstream subscriptions: one upstream connect for many subscribers, then the newest value at once",
          "[gateway][subscriptions]") {
    UpstreamSubscriptions subs;
    SubscriberSessions s;
    const SubKey key{"dev", "w"};
    const SessionRef a = s.make(1), b = s.make(2), late = s.make(3);
    ReadyOutcomes outcomes;

    CHECK_FALSE(subs.join_wire(key, a, outcomes.ready()).ready);
    CHECK(subs.begin_connect(key));
    CHECK_FALSE(subs.join_wire(key, b, outcomes.ready()).ready);
    CHECK_FALSE(subs.begin_connect(key));  // already being connected: one WireConnectReq
    CHECK(outcomes.got.empty());
    answer_all(subs.connect_done(key, {}), {});
    REQUIRE(outcomes.got.size() == 2);
    CHECK(outcomes.got[0].ok());
    CHECK(outcomes.got[1].ok());
    CHECK_FALSE(subs.begin_connect(key));  // connected

    // Values go to every subscriber; the newest is kept for a late one.
    CHECK_FALSE(subs.wire_value(wire_value_entry({"dev", "other"}, 1)));
    auto targets = subs.wire_value(wire_value_entry(key, 7));
    REQUIRE(targets);
    CHECK(*targets->sessions == std::vector<SessionRef>{a, b});
    const auto delivering = targets->sessions;
    subs.wire_value(wire_value_entry(key, 8));
    auto joined = subs.join_wire(key, late, outcomes.ready());
    CHECK(joined.ready);
    REQUIRE(joined.last);
    CHECK(joined.last->entry().request_id == 8);
    CHECK(outcomes.got.size() == 2);  // a ready join keeps no waiter
    CHECK(subs.has_session(key, late));
    CHECK(delivering->size() == 2);  // copied on write: a list being delivered is not changed under it
    CHECK_FALSE(subs.has_session({"dev", "other"}, late));

    // Joining twice does not deliver twice.
    subs.join_wire(key, a, outcomes.ready());
    CHECK(subs.wire_value(wire_value_entry(key, 9))->sessions->size() == 3);
}

TEST_CASE("upstream subscriptions: the last subscriber of either front end disconnects the wire upstream",
          "[gateway][subscriptions]") {
    UpstreamSubscriptions subs;
    SubscriberSessions s;
    const SubKey key{"dev", "w"};
    const SessionRef a = s.make(1), b = s.make(2);
    ReadyOutcomes outcomes;
    subs.join_wire(key, a, outcomes.ready());
    subs.join_wire(key, b, outcomes.ready());
    REQUIRE(subs.begin_connect(key));
    answer_all(subs.connect_done(key, {}), {});
    std::vector<SharedEntryPtr> internal_got;
    auto [id, joined] = subs.add_internal(key, true, [&](const SharedEntryPtr& e) { internal_got.push_back(e); },
                                          outcomes.ready());
    CHECK(joined.ready);

    CHECK_FALSE(subs.leave_wire(key, a));
    CHECK(subs.leave_all(2).empty());  // b's session closed: the internal subscriber is left
    auto targets = subs.wire_value(wire_value_entry(key, 3));
    REQUIRE(targets);
    CHECK(targets->sessions->empty());
    REQUIRE(targets->internal);
    CHECK(targets->internal->size() == 1);
    CHECK(subs.remove_internal(id) == std::vector<SubKey>{key});
    CHECK(subs.wire_count() == 0);

    SECTION("a closed session that was the last subscriber") {
        subs.join_wire(key, a, outcomes.ready());
        REQUIRE(subs.begin_connect(key));
        answer_all(subs.connect_done(key, {}), {});
        CHECK(subs.leave_all(1) == std::vector<SubKey>{key});
        CHECK(subs.wire_count() == 0);
    }
    SECTION("leaving a wire never connected upstream asks for no disconnect") {
        subs.join_wire(key, a, outcomes.ready());
        CHECK_FALSE(subs.leave_wire(key, a));
    }
}

TEST_CASE("upstream subscriptions: a refused or impossible connect fails the waiters", "[gateway][subscriptions]") {
    UpstreamSubscriptions subs;
    SubscriberSessions s;
    const SubKey key{"dev", "w"};
    const SessionRef a = s.make(1);
    ReadyOutcomes outcomes;

    SECTION("refused upstream: sessions dropped, internal subscribers kept for the device's return") {
        subs.join_wire(key, a, outcomes.ready());
        auto [id, joined] = subs.add_internal(key, true, [](const SharedEntryPtr&) {}, outcomes.ready());
        CHECK_FALSE(joined.ready);
        REQUIRE(subs.begin_connect(key));
        const Result<void> refused = fail(MessageErrorType::MemberNotFound, "no such wire");
        answer_all(subs.connect_done(key, refused), refused);
        REQUIRE(outcomes.got.size() == 2);
        CHECK(outcomes.got[0].error().type == MessageErrorType::MemberNotFound);
        CHECK_FALSE(subs.has_session(key, a));
        CHECK(subs.upstream_back() == std::vector<SubKey>{key});
        CHECK(subs.remove_internal(id).empty());  // never connected upstream: nothing to disconnect
        CHECK(subs.wire_count() == 0);
    }
    SECTION("no device connection") {
        subs.join_wire(key, a, outcomes.ready());
        const Result<void> away = fail(MessageErrorType::ConnectionError, "away");
        answer_all(subs.no_upstream(key), away);
        REQUIRE(outcomes.got.size() == 1);
        CHECK(outcomes.got[0].error().type == MessageErrorType::ConnectionError);
    }
    SECTION("the device connection lost while connecting, then back") {
        subs.join_wire(key, a, outcomes.ready());
        REQUIRE(subs.begin_connect(key));
        answer_all(subs.upstream_lost(), fail(MessageErrorType::ConnectionError, "lost"));
        REQUIRE(outcomes.got.size() == 1);
        CHECK_FALSE(outcomes.got[0].ok());
        CHECK(subs.has_session(key, a));  // the subscription stays, to be connected again
        CHECK(subs.upstream_back() == std::vector<SubKey>{key});
        CHECK(subs.begin_connect(key));
    }
}

TEST_CASE("upstream subscriptions: events and WireClosed reach their subscribers", "[gateway][subscriptions]") {
    UpstreamSubscriptions subs;
    SubscriberSessions s;
    const SubKey ev{"dev", "ev"}, key{"dev", "w"};
    auto [id1, j1] = subs.add_internal(ev, false, [](const SharedEntryPtr&) {}, nullptr);
    auto [id2, j2] = subs.add_internal(ev, false, [](const SharedEntryPtr&) {}, nullptr);
    CHECK(j1.ready);
    CHECK(id1 != id2);
    REQUIRE(subs.event_subscribers(ev));
    CHECK(subs.event_subscribers(ev)->size() == 2);
    const auto before = subs.event_subscribers(ev);
    subs.remove_internal(id1);
    CHECK(before->size() == 2);  // copied on write: a list being delivered is not changed under it
    CHECK(subs.event_subscribers(ev)->size() == 1);
    subs.remove_internal(id2);
    CHECK_FALSE(subs.event_subscribers(ev));

    ReadyOutcomes outcomes;
    subs.join_wire(key, s.make(1), outcomes.ready());
    REQUIRE(subs.begin_connect(key));
    answer_all(subs.connect_done(key, {}), {});
    auto closed = subs.wire_closed(key);
    REQUIRE(closed);
    CHECK(closed->sessions->size() == 1);
    CHECK_FALSE(subs.wire_closed(key));
    CHECK(subs.wire_count() == 0);
}

TEST_CASE("upstream subscriptions: a value that came while the wire connects is the newest for a subscriber joining then",
          "[gateway][subscriptions]") {
    // A device sends a wire's value before its WireConnectRet: subscribers joining between the two
    // (the JSON API's, a recording's) must not wait for the next change.
    UpstreamSubscriptions subs;
    SubscriberSessions s;
    const SubKey key{"dev", "w"};
    ReadyOutcomes outcomes;
    auto first = subs.add_internal(key, true, [](const SharedEntryPtr&) {}, outcomes.ready());
    CHECK_FALSE(first.second.ready);
    CHECK_FALSE(first.second.last);
    CHECK(subs.begin_connect(key));
    CHECK_FALSE(subs.newest(key));
    auto targets = subs.wire_value(wire_value_entry(key, 5));  // before the WireConnectRet
    REQUIRE(targets);
    REQUIRE(targets->internal);
    CHECK(targets->internal->size() == 1);
    auto second = subs.add_internal(key, true, [](const SharedEntryPtr&) {}, outcomes.ready());
    CHECK_FALSE(second.second.ready);
    REQUIRE(second.second.last);
    CHECK(second.second.last->entry().request_id == 5);
    // A native session joining now gets no value before its WireConnectRet; newest() is sent after it.
    const SessionRef native = s.make(1);
    auto joined = subs.join_wire(key, native, outcomes.ready());
    CHECK_FALSE(joined.ready);
    CHECK_FALSE(joined.last);
    answer_all(subs.connect_done(key, {}), {});
    CHECK(outcomes.got.size() == 3);
    REQUIRE(subs.newest(key));
    CHECK(subs.newest(key)->entry().request_id == 5);
    CHECK_FALSE(subs.newest({"dev", "other"}));
}
