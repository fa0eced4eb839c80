// Wire members at the entry level: connect (current value first), out value fan-out with packettime,
// in values with time-stamp ordering, peek/poke, directions, WireClosed, disconnect.
#include "server/service/object_service_fixture.hpp"
#include "test/support/eventually.hpp"

#include <thread>

using namespace rr;
using namespace rr::server;
using namespace rr::server::testing;

namespace {

MessageEntry wire_packet(const ServiceFixture& f, const char* member, const Value& v, std::string_view type, TimeSpec t,
                         MessageEntryType entry_type = MessageEntryType::WirePacket) {
    auto e = req(entry_type, member);
    if (entry_type == MessageEntryType::WirePacket) e.metadata = "unreliable\n";
    e.elements.push_back(pack_timespec(t, "packettime"));
    e.elements.push_back(f.pack(v, type, "packet"));
    return e;
}

using rr::testing::eventually;

}  // namespace

TEST_CASE("wires: out value fan-out, current value on connect, time stamps, disconnect, close") {
    ServiceFixture f;
    auto level = f.root->wire("level").value();
    REQUIRE(level->set_out_value(Value::array<double>({1, 2})));
    auto a = f.connect();
    auto b = f.connect();

    // connect: the current out value arrives (before the WireConnectRet, as CORE's broadcaster sends it)
    a.ok(req(MessageEntryType::WireConnectReq, "level"));
    auto first = a.inbox->take(MessageEntryType::WirePacket, 0ms);
    REQUIRE(first);
    CHECK(first->metadata == "unreliable\n");
    CHECK(f.unpack(*first->find("packet"), "double[]") == Value::array<double>({1, 2}));
    auto t0 = unpack_timespec(*first->find("packettime"));
    REQUIRE(t0);
    CHECK(t0->seconds > 1'500'000'000);
    b.ok(req(MessageEntryType::WireConnectReq, "level"));
    REQUIRE(b.inbox->take(MessageEntryType::WirePacket));
    REQUIRE(level->connections().size() == 2);

    // set_out_value reaches every connection with a newer time stamp
    REQUIRE(level->set_out_value(Value::array<double>({3})));
    for (auto* c : {&a, &b}) {
        auto p = c->inbox->take(MessageEntryType::WirePacket);
        REQUIRE(p);
        CHECK(f.unpack(*p->find("packet"), "double[]") == Value::array<double>({3}));
        CHECK(*unpack_timespec(*p->find("packettime")) > *t0);
    }
    // strictly increasing stamps even for back-to-back values
    TimeSpec last{};
    for (int i = 0; i < 5; ++i) {
        REQUIRE(level->set_out_value(Value::array<double>({double(i)})));
        auto t = level->out_value()->time;
        CHECK(t > last);
        last = t;
    }
    // newest wins: whatever was coalesced, the last value arrives
    CHECK(eventually([&] {
        auto p = a.inbox->take(
            [&](const MessageEntry& e) {
                return e.entry_type == MessageEntryType::WirePacket &&
                       f.unpack(*e.find("packet"), "double[]") == Value::array<double>({4});
            },
            0ms);
        return p.has_value();
    }));

    // peek in (the out value) needs no connection
    auto peek = b.ok(req(MessageEntryType::WirePeekInValueReq, "level"));
    CHECK(f.unpack(*peek.find("packet"), "double[]") == Value::array<double>({4}));
    CHECK(peek.metadata.empty());

    // client disconnect; a second one is an error
    a.ok(req(MessageEntryType::WireDisconnectReq, "level"));
    auto again = a.error(req(MessageEntryType::WireDisconnectReq, "level"));
    CHECK(again.type == MessageErrorType::ServiceError);
    CHECK(again.message == "Invalid wire connection");
    CHECK(level->connections().size() == 1);

    // service close: WireClosed
    std::atomic<int> closed{0};
    level->on_close([&](const std::shared_ptr<WireConnection>&) { ++closed; });
    level->connections().at(0)->close();
    auto wc = b.inbox->take(MessageEntryType::WireClosed);
    REQUIRE(wc);
    CHECK(wc->member_name == "level");
    CHECK(closed == 1);
    CHECK(level->connections().empty());
}

TEST_CASE("wires: values set from two threads reach every client in time-stamp order") {
    // A client drops a packet older than the last one it got (wire.md §6.7): two threads setting the out
    // value at once must not let an older stamp reach a client after a newer one (issue 51: the official
    // client missed a value sent while the service's periodic thread sent another).
    ServiceFixture f;
    auto level = f.root->wire("level").value();
    REQUIRE(level->set_out_value(Value::array<double>({0})));
    auto a = f.connect();
    auto b = f.connect();
    for (auto* c : {&a, &b}) {
        c->ok(req(MessageEntryType::WireConnectReq, "level"));
        REQUIRE(c->inbox->take(MessageEntryType::WirePacket));
    }
    constexpr int kValues = 300;
    auto sender = [&](double who) {
        for (int i = 0; i < kValues; ++i) (void)level->set_out_value(Value::array<double>({who, double(i)}));
    };
    std::thread t1(sender, 1.0), t2(sender, 2.0);
    t1.join();
    t2.join();
    const auto newest = level->out_value();
    REQUIRE(newest);
    for (auto* c : {&a, &b}) {
        // Every packet a client got, in arrival order, up to the newest value (newest wins, so some are
        // skipped): strictly increasing stamps, ending with the wire's out value.
        std::vector<TimeSpec> stamps;
        while (stamps.empty() || stamps.back() != newest->time) {
            auto p = c->inbox->take(MessageEntryType::WirePacket, 10000ms);  // a bound on a hang
            REQUIRE(p);
            stamps.push_back(*unpack_timespec(*p->find("packettime")));
            if (stamps.size() > 1) REQUIRE(stamps[stamps.size() - 2] < stamps.back());
        }
        CHECK(c->inbox->count(MessageEntryType::WirePacket) == 0);
    }
}

TEST_CASE("wires: a new connection gets the current value, never after a newer one") {
    // The current value goes to a new client after on_connect; a value set or sent to it in between
    // (here by on_connect itself) is newer, so the current one must not follow it (wire.md §6.7).
    ServiceFixture f;
    auto level = f.root->wire("level").value();
    REQUIRE(level->set_out_value(Value::array<double>({0})));
    bool to_connection = false;
    level->on_connect([&](const std::shared_ptr<WireConnection>& c) -> Result<void> {
        if (to_connection) return c->set_out_value(Value::array<double>({2}));
        return level->set_out_value(Value::array<double>({1}));
    });
    for (bool per_connection : {false, true}) {
        to_connection = per_connection;
        auto c = f.connect();
        c.ok(req(MessageEntryType::WireConnectReq, "level"));
        (void)c.ok(req(MessageEntryType::WirePeekInValueReq, "level"));  // a round trip: all queued
        std::vector<std::pair<TimeSpec, Value>> got;
        while (auto p = c.inbox->take(MessageEntryType::WirePacket, 0ms))
            got.emplace_back(*unpack_timespec(*p->find("packettime")), f.unpack(*p->find("packet"), "double[]"));
        REQUIRE(!got.empty());
        for (std::size_t i = 1; i < got.size(); ++i) CHECK(got[i - 1].first < got[i].first);
        CHECK(got.back().second == Value::array<double>({per_connection ? 2.0 : 1.0}));
    }
}

TEST_CASE("wires: in values, ordering by time stamp, peek out and poke") {
    ServiceFixture f;
    auto level = f.root->wire("level").value();
    std::mutex m;
    std::vector<std::pair<bool, Value>> values;  // (from a connection, value)
    level->on_value([&](const std::shared_ptr<WireConnection>& c, const Value& v, TimeSpec) {
        std::lock_guard lock(m);
        values.emplace_back(c != nullptr, v);
        if (c) (void)c->set_out_value(v);  // echo to that client only
    });
    auto c = f.connect();
    CHECK(c.error(req(MessageEntryType::WirePeekOutValueReq, "level")).type == MessageErrorType::ValueNotSet);
    CHECK(c.error(req(MessageEntryType::WirePeekInValueReq, "level")).type == MessageErrorType::ValueNotSet);

    // packets before connecting are ignored
    c.send(wire_packet(f, "level", Value::array<double>({0}), "double[]", TimeSpec{100, 0}));
    c.ok(req(MessageEntryType::WireConnectReq, "level"));
    c.send(wire_packet(f, "level", Value::array<double>({1}), "double[]", TimeSpec{200, 5}));
    c.send(wire_packet(f, "level", Value::array<double>({2}), "double[]", TimeSpec{200, 4}));  // older: dropped
    c.send(wire_packet(f, "level", Value::array<double>({3}), "double[]", TimeSpec{201, 0}));
    c.send(wire_packet(f, "level", Value("x"), "string", TimeSpec{300, 0}));                 // wrong type: dropped
    auto peek = c.ok(req(MessageEntryType::WirePeekOutValueReq, "level"));  // a round trip: packets handled
    CHECK(f.unpack(*peek.find("packet"), "double[]") == Value::array<double>({3}));
    CHECK(*unpack_timespec(*peek.find("packettime")) == TimeSpec{201, 0});
    {
        std::lock_guard lock(m);
        REQUIRE(values.size() == 2);
        CHECK(values[0].second == Value::array<double>({1}));
        CHECK(values[1].second == Value::array<double>({3}));
    }
    auto conn = level->connections().at(0);
    REQUIRE(conn->in_value());
    CHECK(conn->in_value()->value == Value::array<double>({3}));
    // the per-connection echo
    CHECK(c.inbox->take(MessageEntryType::WirePacket));

    // poke sets the in value and runs on_value without a connection
    c.ok(wire_packet(f, "level", Value::array<double>({9}), "double[]", TimeSpec{5, 0}, MessageEntryType::WirePokeOutValueReq));
    CHECK(level->in_value()->value == Value::array<double>({9}));
    {
        std::lock_guard lock(m);
        REQUIRE(values.size() == 3);
        CHECK_FALSE(values[2].first);
    }
    auto bad_poke = req(MessageEntryType::WirePokeOutValueReq, "level");
    bad_poke.elements.push_back(pack_timespec(TimeSpec{1, 0}, "packettime"));
    CHECK(c.error(bad_poke).type == MessageErrorType::MessageElementNotFound);
    CHECK(c.error(wire_packet(f, "level", Value("x"), "string", TimeSpec{1, 0}, MessageEntryType::WirePokeOutValueReq)).type ==
          MessageErrorType::DataTypeError);

    // handlers replace the peek/poke defaults
    level->set_peek_in_handler([](const SessionRef&) -> Result<TimedValue> { return TimedValue{Value::array<double>({7}), TimeSpec{1, 2}}; });
    auto pi = c.ok(req(MessageEntryType::WirePeekInValueReq, "level"));
    CHECK(f.unpack(*pi.find("packet"), "double[]") == Value::array<double>({7}));
    level->set_poke_handler([](const SessionRef&, Value, TimeSpec) -> Result<void> { return fail(MessageErrorType::InvalidOperation, "no"); });
    CHECK(c.error(wire_packet(f, "level", Value::array<double>({1}), "double[]", TimeSpec{1, 0}, MessageEntryType::WirePokeOutValueReq)).type ==
          MessageErrorType::InvalidOperation);
}

TEST_CASE("wires: direction rules for [readonly] and [writeonly]") {
    ServiceFixture f;
    auto state = f.root->wire("state").value();     // [readonly]: clients only read
    auto in_only = f.root->wire("in_only").value();  // [writeonly]: clients only write
    std::atomic<int> state_values{0};
    state->on_value([&](const std::shared_ptr<WireConnection>&, const Value&, TimeSpec) { ++state_values; });
    REQUIRE(state->set_out_value(pt(1, 2)));
    CHECK(in_only->set_out_value(Value::scalar<std::int32_t>(1)).error().type == MessageErrorType::ReadOnlyMember);
    auto c = f.connect();

    c.ok(req(MessageEntryType::WireConnectReq, "state"));
    CHECK(c.inbox->take(MessageEntryType::WirePacket));
    CHECK(c.error(req(MessageEntryType::WirePeekOutValueReq, "state")).type == MessageErrorType::ReadOnlyMember);
    CHECK(c.error(wire_packet(f, "state", pt(0, 0), "Pt", TimeSpec{1, 0}, MessageEntryType::WirePokeOutValueReq)).type ==
          MessageErrorType::ReadOnlyMember);
    c.send(wire_packet(f, "state", pt(0, 0), "Pt", TimeSpec{1, 0}));  // ignored
    auto pi = c.ok(req(MessageEntryType::WirePeekInValueReq, "state"));
    CHECK(f.unpack(*pi.find("packet"), "Pt") == pt(1, 2));
    CHECK(state_values == 0);

    c.ok(req(MessageEntryType::WireConnectReq, "in_only"));
    CHECK(c.error(req(MessageEntryType::WirePeekInValueReq, "in_only")).type == MessageErrorType::WriteOnlyMember);
    c.send(wire_packet(f, "in_only", Value::scalar<std::int32_t>(42), "int32", TimeSpec{1, 0}));
    auto po = c.ok(req(MessageEntryType::WirePeekOutValueReq, "in_only"));
    CHECK(f.unpack(*po.find("packet"), "int32") == Value::scalar<std::int32_t>(42));
    CHECK(in_only->in_value()->value == Value::scalar<std::int32_t>(42));
    CHECK(c.error(req(MessageEntryType::WireConnectReq, "samples")).type == MessageErrorType::MemberNotFound);  // a pipe
}
