// A JSON WebSocket's subscription registry (json_subscriptions.hpp): ids and limits, the answered state,
// and the push policy (drops counted and reported, wire values coalesced) without a socket.
#include <catch2/catch.hpp>

#include "core/session/elements.hpp"
#include "server/gateway/json_subscriptions.hpp"
#include "server/gateway/wire_value_test_support.hpp"

using namespace rr;
using namespace rr::server::gateway;

namespace {

JsonSubscription subscription(SubscriptionKind kind, std::shared_ptr<SessionEndpoints> own = nullptr) {
    JsonSubscription s;
    s.kind = kind;
    s.target = std::make_shared<const MemberTarget>();
    s.own = std::move(own);
    return s;
}

std::uint64_t add(JsonSubscriptions& subs, JsonSubscription s, bool active = true) {
    auto added = subs.add(std::move(s));
    REQUIRE(std::holds_alternative<std::uint64_t>(added));
    const auto sid = std::get<std::uint64_t>(added);
    subs.find(sid)->active = active;
    return sid;
}

constexpr auto wire_value = rr::server::gateway::testing::wire_packet_value;

}  // namespace

TEST_CASE("json subscriptions: ids from 1 never reused, and the per-socket limit") {
    JsonSubscriptions subs(2);
    const auto a = add(subs, subscription(SubscriptionKind::wire));
    const auto b = add(subs, subscription(SubscriptionKind::event));
    CHECK(a == 1);
    CHECK(b == 2);
    auto over = subs.add(subscription(SubscriptionKind::pipe));
    REQUIRE(std::holds_alternative<ApiError>(over));
    CHECK(std::get<ApiError>(over).name == "RobotRaconteur.BufferLimitViolation");
    CHECK(std::get<ApiError>(over).message == "more than 2 subscriptions on this socket");
    subs.erase(a);
    CHECK(add(subs, subscription(SubscriptionKind::pipe)) == 3);
    CHECK(subs.size() == 2);
    CHECK(subs.find(a) == nullptr);
}

TEST_CASE("json subscriptions: only answered subscriptions are found for sending and unsubscribing") {
    JsonSubscriptions subs(8);
    const auto waiting = add(subs, subscription(SubscriptionKind::wire), false);
    const auto wire = add(subs, subscription(SubscriptionKind::wire));

    auto none = subs.find_active(waiting, SubscriptionKind::wire);
    REQUIRE(std::holds_alternative<ApiError>(none));
    CHECK(std::get<ApiError>(none).message == "no subscription 1");
    auto other_kind = subs.find_active(wire, SubscriptionKind::event);
    REQUIRE(std::holds_alternative<ApiError>(other_kind));
    CHECK(std::get<ApiError>(other_kind).message == "subscription 2 is a wire subscription, not an event");
    CHECK(std::holds_alternative<const JsonSubscription*>(subs.find_active(wire, SubscriptionKind::wire)));

    CHECK_FALSE(subs.take_active(waiting));
    CHECK(subs.find(waiting) != nullptr);  // still waiting for its reply
    auto taken = subs.take_active(wire);
    REQUIRE(taken);
    CHECK(taken->kind == SubscriptionKind::wire);
    CHECK_FALSE(subs.is_active(wire));
    CHECK(subs.size() == 1);
}

TEST_CASE("json subscriptions: pushes dropped while congested are counted and reported by the next one") {
    JsonSubscriptions subs(8);
    const auto waiting = add(subs, subscription(SubscriptionKind::event), false);
    const auto sid = add(subs, subscription(SubscriptionKind::event));

    CHECK_FALSE(subs.take_push(waiting, false));  // no push before the subscribe reply
    CHECK_FALSE(subs.take_push(99, false));
    CHECK(subs.push_drops() == 0);

    CHECK_FALSE(subs.take_push(sid, true));
    CHECK_FALSE(subs.take_push(sid, true));
    CHECK(subs.push_drops() == 2);
    auto ticket = subs.take_push(sid, false);
    REQUIRE(ticket);
    CHECK(ticket->dropped == 2);
    CHECK(ticket->target == subs.find(sid)->target);
    auto next = subs.take_push(sid, false);
    REQUIRE(next);
    CHECK(next->dropped == 0);

    // Taken, then dropped after all (no room to convert it): its count goes back, plus itself.
    subs.return_push(sid, 0);
    auto after = subs.take_push(sid, false);
    REQUIRE(after);
    CHECK(after->dropped == 1);
    CHECK(subs.push_drops() == 3);
}

TEST_CASE("json subscriptions: the newest wire value waits, older ones are coalesced") {
    JsonSubscriptions subs(8);
    const auto sid = add(subs, subscription(SubscriptionKind::wire), false);
    CHECK_FALSE(subs.offer_wire(42, wire_value(0)).send_now);  // not a subscription

    CHECK_FALSE(subs.offer_wire(sid, wire_value(1)).send_now);  // kept until the subscribe reply
    CHECK_FALSE(subs.offer_wire(sid, wire_value(2)).send_now);
    CHECK(subs.wire_coalesced() == 1);
    CHECK(subs.pending_wires() == 1);
    CHECK_FALSE(subs.wires_waiting());  // not answered yet: nothing to send

    subs.find(sid)->active = true;
    CHECK(subs.wires_waiting());
    CHECK(subs.offer_wire(sid, wire_value(3)).send_now);
    CHECK(subs.wire_coalesced() == 2);

    std::vector<WireToSend> batch{WireToSend{}};
    subs.take_wires(batch);
    REQUIRE(batch.size() == 1);
    CHECK(batch[0].subscription == sid);
    double v = 0;
    REQUIRE(read_scalar(*batch[0].value->entry().find("packet"), v));
    CHECK(v == 3);
    CHECK(subs.pending_wires() == 0);
    subs.take_wires(batch);
    CHECK(batch.empty());
}

TEST_CASE("json subscriptions: a rate group's value older than one offered before (its seq not above) is dropped and counted") {
    JsonSubscriptions subs(8);
    const auto sid = add(subs, subscription(SubscriptionKind::wire));
    std::vector<WireToSend> batch;
    auto sent = [&] {
        subs.take_wires(batch);
        REQUIRE(batch.size() == 1);
        double v = 0;
        REQUIRE(read_scalar(*batch[0].value->entry().find("packet"), v));
        return v;
    };
    CHECK(subs.offer_wire(sid, wire_value(5), {}, 0, 5).send_now);
    CHECK(sent() == 5);
    CHECK_FALSE(subs.offer_wire(sid, wire_value(4), {}, 2, 4).send_now);  // handed out late: older than 5
    CHECK_FALSE(subs.offer_wire(sid, wire_value(5), {}, 0, 5).send_now);  // the same one again
    CHECK(subs.pending_wires() == 0);
    CHECK(subs.wire_coalesced() == 4);  // the 2 its group replaced before value 4, and the two dropped here
    CHECK(subs.offer_wire(sid, wire_value(7), {}, 1, 7).send_now);
    CHECK(sent() == 7);
    CHECK(subs.wire_coalesced() == 5);
    CHECK(subs.offer_wire(sid, wire_value(8)).send_now);  // no group (seq 0): no order to keep
    CHECK(sent() == 8);
}

TEST_CASE("json subscriptions: a device login's subscriptions end with it, the shared ones stay") {
    JsonSubscriptions subs(8);
    // The login's session: never called here, only compared.
    auto login = std::make_shared<SessionEndpoints>(SessionEndpoints::Upstream{});
    const auto shared = add(subs, subscription(SubscriptionKind::wire));
    const auto answered = add(subs, subscription(SubscriptionKind::event, login));
    add(subs, subscription(SubscriptionKind::pipe, login), false);

    auto ended = subs.remove_own(login);
    CHECK(ended == std::vector<std::uint64_t>{answered});  // only answered ones get a "closed" push
    CHECK(subs.size() == 1);
    CHECK(subs.is_active(shared));

    auto all = subs.take_all();
    CHECK(all.size() == 1);
    CHECK(subs.size() == 0);
}

TEST_CASE("json subscriptions: a wire's newest handed out on joining after a newer value (ordered by arrival) is dropped") {
    JsonSubscriptions subs(8);
    const auto sid = add(subs, subscription(SubscriptionKind::wire));
    const auto joined_newest = wire_value(1);  // the wire's newest when the subscriber joined
    const auto newer = wire_value(2);          // arrived from the device after it
    REQUIRE(newer->arrival() > joined_newest->arrival());
    std::vector<WireToSend> batch;
    CHECK(subs.offer_wire(sid, newer, {}, 0, newer->arrival()).send_now);  // fanned out first
    subs.take_wires(batch);
    REQUIRE(batch.size() == 1);
    CHECK(batch[0].value == newer);
    CHECK_FALSE(subs.offer_wire(sid, joined_newest, {}, 0, joined_newest->arrival()).send_now);
    CHECK(subs.pending_wires() == 0);
    CHECK(subs.wire_coalesced() == 1);
}
