// Pipe members at the entry level: connect (index rules, unreliable), packets both ways with
// packet numbers and acks, service-side close, disconnect, direction, backlog limit.
#include "server/service/object_service_fixture.hpp"
#include "test/support/eventually.hpp"

#include <thread>

using namespace rr;
using namespace rr::server;
using namespace rr::server::testing;

namespace {

MessageEntry connect_req(const char* member, std::int32_t index, bool unreliable = false) {
    auto e = req(MessageEntryType::PipeConnectReq, member);
    e.elements.push_back(make_scalar_element<std::int32_t>("index", index));
    if (unreliable) e.elements.push_back(make_scalar_element<std::int32_t>("unreliable", 1));
    return e;
}

MessageEntry packet(const ServiceFixture& f, const char* member, std::int32_t index, std::uint32_t number,
                    const Value& v, std::string_view type, bool ack) {
    auto e = req(MessageEntryType::PipePacket, member);
    MessageElement pe;
    pe.name = std::to_string(index);
    pe.type = DataTypes::dictionary_t;
    pe.elements.push_back(make_scalar_element<std::uint32_t>("packetnumber", number));
    pe.elements.push_back(f.pack(v, type, "packet"));
    if (ack) pe.elements.push_back(make_scalar_element<std::uint32_t>("requestack", 1));
    e.elements.push_back(std::move(pe));
    return e;
}

struct Seen {
    std::mutex m;
    std::vector<std::pair<std::int32_t, Value>> packets;
    std::vector<std::uint32_t> acks;
    std::vector<std::int32_t> connected, closed;
    int echo_failures = 0;  // counted on the io thread, checked on the test thread (Catch2 is not thread-safe)
};

}  // namespace

TEST_CASE("pipes: connect, echo with packet numbers and acks, service close, disconnect") {
    auto seen = std::make_shared<Seen>();
    ServiceFixture f([seen](ServiceFixture& f) {
        auto p = f.root->pipe("samples").value();
        p->on_connect([seen](const std::shared_ptr<PipeEndpoint>& ep) -> Result<void> {
            std::lock_guard lock(seen->m);
            seen->connected.push_back(ep->index());
            return {};
        });
        p->on_packet([seen](const std::shared_ptr<PipeEndpoint>& ep, Value v) {
            // No REQUIRE here: this runs on a node io thread and Catch2 v2 assertions are not thread-safe
            // (TSan reported the race on Catch's RunContext); the test thread checks echo_failures.
            // Recorded before the echo goes out: the echo is written to the socket at once (the pump
            // writes directly), so the test thread may see it before this handler returns.
            {
                std::lock_guard lock(seen->m);
                seen->packets.emplace_back(ep->index(), v);
            }
            const bool sent = static_cast<bool>(ep->send(v));  // echo
            std::lock_guard lock(seen->m);
            if (!sent) ++seen->echo_failures;
        });
        p->on_ack([seen](const std::shared_ptr<PipeEndpoint>&, std::uint32_t n) {
            std::lock_guard lock(seen->m);
            seen->acks.push_back(n);
        });
        p->on_close([seen](const std::shared_ptr<PipeEndpoint>& ep) {
            std::lock_guard lock(seen->m);
            seen->closed.push_back(ep->index());
        });
    });
    auto pipe = f.root->pipe("samples").value();
    auto c = f.connect();

    // index −1: the service picks 1, then the client's highest + 1
    CHECK(scalar_of<std::int32_t>(c.ok(connect_req("samples", -1)), "index") == 1);
    CHECK(scalar_of<std::int32_t>(c.ok(connect_req("samples", -1)), "index") == 2);
    CHECK(scalar_of<std::int32_t>(c.ok(connect_req("samples", 5)), "index") == 5);
    CHECK(scalar_of<std::int32_t>(c.ok(connect_req("samples", 5)), "index") == 6);  // in use: highest + 1 (CORE)
    CHECK(pipe->endpoints().size() == 4);
    {
        std::lock_guard lock(seen->m);
        CHECK(seen->connected == std::vector<std::int32_t>{1, 2, 5, 6});
    }

    // client packets with requestack: delivered to on_packet, acknowledged with PipePacketRet
    c.send(packet(f, "samples", 1, 1, Value::array<double>({1, 2}), "double[]", true));
    c.send(packet(f, "samples", 1, 2, Value::array<double>({3}), "double[]", false));
    auto ack = c.inbox->take(MessageEntryType::PipePacketRet);
    REQUIRE(ack);
    REQUIRE(ack->elements.size() == 1);
    CHECK(ack->elements[0].number == 1);  // the pipe index
    std::uint32_t acked = 0;
    CHECK(read_scalar(ack->elements[0], acked));
    CHECK(acked == 1);
    // echoes carry the service's own packet numbers, from 1
    for (std::uint32_t n : {1u, 2u}) {
        auto echo = c.inbox->take(MessageEntryType::PipePacket);
        REQUIRE(echo);
        CHECK(echo->service_path == "svc");
        REQUIRE(echo->elements.size() == 1);
        const auto& pe = echo->elements[0];
        CHECK(pe.name == "1");
        CHECK(pe.type == DataTypes::dictionary_t);
        std::uint32_t number = 0;
        CHECK(read_scalar(*pe.find("packetnumber"), number));
        CHECK(number == n);
        CHECK_FALSE(pe.find("requestack"));
    }
    {
        std::lock_guard lock(seen->m);
        REQUIRE(seen->packets.size() == 2);
        CHECK(seen->packets[0].second == Value::array<double>({1, 2}));
    }

    // the service asks for an ack; the client's PipePacketRet reaches on_ack
    auto ep5 = pipe->endpoints().at(2);
    REQUIRE(ep5->index() == 5);
    auto number = ep5->send(Value::array<double>({9}), true);
    REQUIRE(number);
    CHECK(*number == 1);
    auto sent = c.inbox->take(MessageEntryType::PipePacket);
    REQUIRE(sent);
    CHECK(sent->elements[0].find("requestack"));
    auto ret = req(MessageEntryType::PipePacketRet, "samples");
    MessageElement a = make_scalar_element<std::uint32_t>("", *number);
    a.number = 5;
    ret.elements.push_back(a);
    c.send(ret);
    rr::testing::eventually([&] {
        std::lock_guard lock(seen->m);
        return !seen->acks.empty();
    });
    {
        std::lock_guard lock(seen->m);
        CHECK(seen->acks == std::vector<std::uint32_t>{1});
        CHECK(seen->echo_failures == 0);
    }

    // service-side close: PipeClosed, on_close, sends refused
    ep5->close();
    auto closed = c.inbox->take(MessageEntryType::PipeClosed);
    REQUIRE(closed);
    CHECK(scalar_of<std::int32_t>(*closed, "index") == 5);
    CHECK_FALSE(ep5->is_open());
    CHECK(ep5->send(Value::array<double>({1})).error().type == MessageErrorType::InvalidOperation);
    ep5->close();  // idempotent

    // client disconnect
    auto disc = req(MessageEntryType::PipeDisconnectReq, "samples");
    disc.elements.push_back(make_scalar_element<std::int32_t>("index", 2));
    c.ok(disc);
    auto bad = c.error(disc);
    CHECK(bad.type == MessageErrorType::InvalidArgument);
    CHECK(bad.message == "Invalid pipe");
    CHECK(c.error(req(MessageEntryType::PipeConnectReq, "samples")).type == MessageErrorType::MessageElementNotFound);
    CHECK(c.error(connect_req("level", -1)).type == MessageErrorType::MemberNotFound);  // a wire

    // a packet of the wrong type is dropped (not delivered, not acknowledged)
    c.send(packet(f, "samples", 1, 3, Value("text"), "string", true));
    c.send(packet(f, "samples", 77, 1, Value::array<double>({1}), "double[]", true));  // unknown index
    CHECK(scalar_of<std::int32_t>(c.ok(connect_req("samples", -1)), "index") == 7);  // a round trip: packets were handled
    CHECK(c.inbox->count(MessageEntryType::PipePacketRet) == 0);

    // the session ends: its endpoints close (on_close runs for each)
    c.raw->close();
    CHECK(rr::testing::eventually([&] { return pipe->endpoints().empty(); }));
    std::lock_guard lock(seen->m);
    CHECK(seen->closed.size() == 5);
}

TEST_CASE("pipes: unreliable, readonly and connect refusal") {
    ServiceFixture f([](ServiceFixture& f) {
        f.root->pipe("lossy").value()->on_packet([](const std::shared_ptr<PipeEndpoint>& ep, Value v) { (void)ep->send(v); });
        f.root->pipe("feed").value()->on_packet([](const std::shared_ptr<PipeEndpoint>&, Value) { FAIL("readonly pipe delivered a packet"); });
    });
    auto c = f.connect();
    auto r = c.ok(connect_req("lossy", -1, true));
    CHECK(scalar_of<std::int32_t>(r, "unreliable") == 1);
    c.send(packet(f, "lossy", 1, 1, Value("u1"), "string", false));
    auto echo = c.inbox->take(MessageEntryType::PipePacket);
    REQUIRE(echo);
    CHECK(echo->metadata == "unreliable\n");
    // a reliable pipe never grants unreliable
    CHECK_FALSE(c.ok(connect_req("samples", -1, true)).find("unreliable"));

    // [readonly]: the service sends, client packets are ignored (still acknowledged, as CORE)
    c.ok(connect_req("feed", -1));
    c.send(packet(f, "feed", 1, 1, Value::scalar(1.0), "double", true));
    auto ack = c.inbox->take(MessageEntryType::PipePacketRet);
    REQUIRE(ack);
    auto feed = f.root->pipe("feed").value();
    REQUIRE(feed->broadcast(Value::scalar(2.5)) == 1);
    auto p = c.inbox->take([](const MessageEntry& e) { return e.entry_type == MessageEntryType::PipePacket && e.member_name == "feed"; });
    REQUIRE(p);
    CHECK(f.unpack(*p->elements[0].find("packet"), "double") == Value::scalar(2.5));
    CHECK(feed->endpoints().at(0)->send(Value("x")).error().type == MessageErrorType::DataTypeMismatch);

    // a connect handler may refuse
    f.root->pipe("samples").value()->on_connect([](const std::shared_ptr<PipeEndpoint>&) -> Result<void> {
        return fail(MessageErrorType::PermissionDenied, "no");
    });
    CHECK(c.error(connect_req("samples", -1)).type == MessageErrorType::PermissionDenied);
    CHECK(f.root->pipe("samples").value()->endpoints().size() == 1);  // the earlier one only
}

TEST_CASE("pipes: a full backlog is refused with BufferLimitViolation, never dropped silently") {
    ServiceFixture f;
    auto pipe = f.root->pipe("samples").value();
    pipe->set_max_backlog_bytes(256 * 1024);
    auto c = f.connect();
    c.ok(connect_req("samples", -1));
    // The client stops reading (its strand is blocked in the hook) so the service's queue grows.
    std::promise<void> release;
    auto released = release.get_future().share();
    // Owned by the hook: the client's thread may still run it while this test's locals unwind.
    auto blocked = std::make_shared<std::atomic<bool>>(false);
    *c.hook = [released, blocked](MessageEntry&) {
        if (!blocked->exchange(true)) released.wait();
        return true;
    };
    auto ep = pipe->endpoints().at(0);
    std::vector<double> big(8192, 1.0);  // 64 KiB per packet
    const Value v = Value(NumericArray::from<double>(std::span<const double>(big)));
    std::optional<RRError> refused;
    std::uint32_t last = 0;
    for (int i = 0; i < 4000 && !refused; ++i) {
        auto r = ep->send(v);
        if (r) {
            CHECK(*r == last + 1);  // numbers stay dense: a refused packet takes no number
            last = *r;
        } else {
            refused = r.error();
        }
    }
    REQUIRE(refused);
    CHECK(refused->type == MessageErrorType::BufferLimitViolation);
    CHECK(refused->message.rfind("pipe backlog full", 0) == 0);
    release.set_value();
}
