// SessionEndpoints: a JSON API client's wire connections, event subscriptions and pipe endpoints on its
// own session to a passthrough device, driven by hand (the upstream is a recorder, replies are given
// by the test).
#include <catch2/catch.hpp>

#include <deque>

#include "base/message/error_entry.hpp"
#include "core/session/elements.hpp"
#include "server/gateway/pipe_entries.hpp"
#include "server/gateway/session_endpoints.hpp"

using namespace rr;
using namespace rr::server::gateway;

namespace {

struct FakeUpstreamSession {
    struct Pending {
        MessageEntry request;
        std::function<void(Result<MessageEntry>)> done;
    };
    std::deque<Pending> requests;
    std::vector<MessageEntry> sent;
    bool gone = false;

    std::shared_ptr<SessionEndpoints> make() {
        SessionEndpoints::Upstream u;
        u.request = [this](MessageEntry e, std::function<void(Result<MessageEntry>)> k) {
            if (gone) return k(fail(MessageErrorType::ConnectionError, "gone"));
            requests.push_back(Pending{std::move(e), std::move(k)});
        };
        u.send = [this](MessageEntry e) -> Result<void> {
            if (gone) return fail(MessageErrorType::ConnectionError, "gone");
            sent.push_back(std::move(e));
            return {};
        };
        u.queued_bytes = [] { return std::size_t{0}; };
        return std::make_shared<SessionEndpoints>(std::move(u));
    }
    // Answers the oldest request with `reply` (the request's header, plus `elements`).
    MessageEntry answer(std::vector<MessageElement> elements = {}) {
        REQUIRE_FALSE(requests.empty());
        Pending p = std::move(requests.front());
        requests.pop_front();
        MessageEntry reply = reply_to(p.request);
        reply.elements = std::move(elements);
        p.done(reply);
        return p.request;
    }
    void refuse(RRError error) {
        REQUIRE_FALSE(requests.empty());
        Pending p = std::move(requests.front());
        requests.pop_front();
        MessageEntry reply = reply_to(p.request);
        set_entry_error(reply, error);
        p.done(reply);
    }
};

MessageEntry endpoints_wire_packet(double v) {
    MessageEntry e;
    e.entry_type = MessageEntryType::WirePacket;
    e.service_path = "arm";
    e.member_name = "w";
    e.elements.push_back(make_scalar_element<double>("packet", v));
    return e;
}

}  // namespace

TEST_CASE("session endpoints: one wire connection for two subscriptions, disconnected after the last") {
    FakeUpstreamSession fake;
    auto ep = fake.make();
    std::vector<double> got1, got2;
    std::optional<Result<std::uint64_t>> r1, r2;
    auto on = [](std::vector<double>& into) {
        SubscriptionHandlers h;
        h.on_entry = [&into](const SharedEntryPtr& e) {
            double v = 0;
            REQUIRE(read_scalar(*e->entry().find("packet"), v));
            into.push_back(v);
        };
        return h;
    };
    ep->subscribe("arm", "w", true, on(got1), [&](Result<std::uint64_t> r) { r1 = r; });
    ep->subscribe("arm", "w", true, on(got2), [&](Result<std::uint64_t> r) { r2 = r; });
    REQUIRE(fake.requests.size() == 1);  // one WireConnectReq for both
    CHECK(fake.requests.front().request.entry_type == MessageEntryType::WireConnectReq);
    CHECK_FALSE(r1);
    fake.answer();
    REQUIRE(r1);
    REQUIRE(r2);
    REQUIRE(r1->ok());
    REQUIRE(r2->ok());
    ep->deliver(endpoints_wire_packet(1.5));
    CHECK(got1 == std::vector<double>{1.5});
    CHECK(got2 == std::vector<double>{1.5});

    // Sending needs the connection; a wire this session has not connected is refused.
    CHECK(ep->send_wire_packet(endpoints_wire_packet(2)).ok());
    CHECK(fake.sent.size() == 1);
    MessageEntry other = endpoints_wire_packet(2);
    other.member_name = "v";
    auto refused = ep->send_wire_packet(std::move(other));
    REQUIRE_FALSE(refused.ok());
    CHECK(refused.error().type == MessageErrorType::InvalidOperation);

    ep->unsubscribe(**r1);
    CHECK(fake.requests.empty());  // the other subscription still uses it
    ep->deliver(endpoints_wire_packet(2.5));
    CHECK(got1 == std::vector<double>{1.5});
    CHECK(got2 == std::vector<double>{1.5, 2.5});
    ep->unsubscribe(**r2);
    REQUIRE(fake.requests.size() == 1);
    CHECK(fake.requests.front().request.entry_type == MessageEntryType::WireDisconnectReq);
    CHECK(fake.requests.front().request.member_name == "w");
}

TEST_CASE("session endpoints: a refused wire connect fails every waiting subscription with the device's error") {
    FakeUpstreamSession fake;
    auto ep = fake.make();
    std::optional<Result<std::uint64_t>> r1, r2;
    ep->subscribe("arm", "w", true, {}, [&](Result<std::uint64_t> r) { r1 = r; });
    ep->subscribe("arm", "w", true, {}, [&](Result<std::uint64_t> r) { r2 = r; });
    fake.refuse(make_error(MessageErrorType::ObjectLockedError, "Object locked by alice"));
    REQUIRE(r1);
    REQUIRE(r2);
    REQUIRE_FALSE(r1->ok());
    CHECK(r1->error().type == MessageErrorType::ObjectLockedError);
    CHECK(r2->error().message == "Object locked by alice");
    // Nothing is left: the next subscription connects again.
    ep->subscribe("arm", "w", true, {}, [](Result<std::uint64_t>) {});
    CHECK(fake.requests.size() == 1);
}

TEST_CASE("session endpoints: events need no request, and WireClosed or a lost session closes subscriptions once") {
    FakeUpstreamSession fake;
    auto ep = fake.make();
    int events = 0;
    std::vector<std::string> closed;
    SubscriptionHandlers he;
    he.on_entry = [&](const SharedEntryPtr&) { ++events; };
    he.on_closed = [&](const RRError& e) { closed.push_back("event: " + e.message); };
    std::optional<Result<std::uint64_t>> re;
    ep->subscribe("arm", "ev", false, he, [&](Result<std::uint64_t> r) { re = r; });
    REQUIRE(re);
    REQUIRE(re->ok());
    CHECK(fake.requests.empty());
    MessageEntry ev;
    ev.entry_type = MessageEntryType::EventReq;
    ev.service_path = "arm";
    ev.member_name = "ev";
    ep->deliver(MessageEntry(ev));
    ev.member_name = "other";
    ep->deliver(MessageEntry(ev));
    CHECK(events == 1);

    SubscriptionHandlers hw;
    hw.on_closed = [&](const RRError& e) { closed.push_back("wire: " + e.message); };
    ep->subscribe("arm", "w", true, hw, [](Result<std::uint64_t>) {});
    fake.answer();
    MessageEntry wc;
    wc.entry_type = MessageEntryType::WireClosed;
    wc.service_path = "arm";
    wc.member_name = "w";
    ep->deliver(std::move(wc));
    REQUIRE(closed.size() == 1);
    CHECK(closed[0] == "wire: wire closed by the device");

    ep->lost(make_error(MessageErrorType::ConnectionError, "the device closed this client's session"));
    ep->lost(make_error(MessageErrorType::ConnectionError, "again"));
    REQUIRE(closed.size() == 2);
    CHECK(closed[1] == "event: the device closed this client's session");
    std::optional<Result<std::uint64_t>> late;
    ep->subscribe("arm", "ev", false, {}, [&](Result<std::uint64_t> r) { late = r; });
    REQUIRE(late);
    REQUIRE_FALSE(late->ok());
    CHECK(late->error().type == MessageErrorType::ConnectionError);
}

TEST_CASE("session endpoints: a pipe endpoint numbers its packets, acknowledges what the device asks, and hears acks") {
    FakeUpstreamSession fake;
    auto ep = fake.make();
    std::vector<std::string> packets;
    std::vector<std::uint32_t> acks;
    std::optional<std::string> closed;
    GatewayPipeHandlers h;
    h.on_packet = [&](const MessageElement& p, std::uint32_t n) { packets.push_back(std::string(read_string(p)) + "#" + std::to_string(n)); };
    h.on_ack = [&](std::uint32_t n) { acks.push_back(n); };
    h.on_closed = [&](const RRError& e) { closed = e.message; };
    std::optional<Result<std::uint64_t>> opened;
    ep->open_pipe("arm", "p", false, h, [&](Result<std::uint64_t> r) { opened = r; });
    REQUIRE(fake.requests.size() == 1);
    CHECK(fake.requests.front().request.entry_type == MessageEntryType::PipeConnectReq);
    CHECK(entry_pipe_index(fake.requests.front().request) == -1);
    fake.answer({make_scalar_element<std::int32_t>("index", 7)});
    REQUIRE(opened);
    REQUIRE(opened->ok());
    const std::uint64_t id = **opened;

    auto n1 = ep->send_pipe_packet(id, make_string_element("x", "a"), false);
    auto n2 = ep->send_pipe_packet(id, make_string_element("x", "b"), true);
    REQUIRE(n1.ok());
    REQUIRE(n2.ok());
    CHECK(*n1 == 1);
    CHECK(*n2 == 2);
    REQUIRE(fake.sent.size() == 2);
    CHECK(fake.sent[1].elements.at(0).name == "7");
    CHECK(fake.sent[1].elements.at(0).find("requestack") != nullptr);

    // The device's packet asks for an ack: it is sent back, numbered by the endpoint's index.
    MessageElement packet = make_string_element("x", "from device");
    MessageEntry in = pipe_packet_entry("arm", "p", 7, 5, packet, true, false);
    MessageEntry stray = pipe_packet_entry("arm", "p", 8, 1, packet, false, false);  // not ours: ignored
    in.elements.push_back(std::move(stray.elements.at(0)));
    ep->deliver(std::move(in));
    CHECK(packets == std::vector<std::string>{"from device#5"});
    REQUIRE(fake.sent.size() == 3);
    CHECK(fake.sent[2].entry_type == MessageEntryType::PipePacketRet);
    REQUIRE(fake.sent[2].elements.size() == 1);
    CHECK(fake.sent[2].elements[0].number == 7);

    MessageEntry ret;
    ret.entry_type = MessageEntryType::PipePacketRet;
    ret.service_path = "arm";
    ret.member_name = "p";
    ret.elements.push_back(pipe_ack_element(7, 2));
    ep->deliver(std::move(ret));
    CHECK(acks == std::vector<std::uint32_t>{2});

    MessageEntry pc;
    pc.entry_type = MessageEntryType::PipeClosed;
    pc.service_path = "arm";
    pc.member_name = "p";
    pc.elements.push_back(make_scalar_element<std::int32_t>("index", 7));
    ep->deliver(std::move(pc));
    CHECK(closed == "pipe endpoint closed by the device");
    auto after = ep->send_pipe_packet(id, make_string_element("x", "c"), false);
    REQUIRE_FALSE(after.ok());
    CHECK(after.error().type == MessageErrorType::InvalidArgument);
}

TEST_CASE("session endpoints: a pipe closed while connecting is disconnected when the device answers") {
    FakeUpstreamSession fake;
    auto ep = fake.make();
    std::optional<Result<std::uint64_t>> opened;
    ep->open_pipe("arm", "p", false, {}, [&](Result<std::uint64_t> r) { opened = r; });
    // The owner learns the id only from `done`; ids are handed out in order, so the first is 1.
    ep->close_pipe(1);
    fake.answer({make_scalar_element<std::int32_t>("index", 3)});
    REQUIRE(opened);
    REQUIRE_FALSE(opened->ok());
    CHECK(opened->error().type == MessageErrorType::OperationAborted);
    REQUIRE(fake.requests.size() == 1);
    CHECK(fake.requests.front().request.entry_type == MessageEntryType::PipeDisconnectReq);
    CHECK(entry_pipe_index(fake.requests.front().request) == 3);
}

TEST_CASE("session endpoints: on a shared session they take their own pipe elements and leave the rest") {
    FakeUpstreamSession fake;
    auto ep = fake.make();
    std::vector<std::string> packets;
    std::vector<std::uint32_t> acks;
    int closed = 0;
    GatewayPipeHandlers h;
    h.on_packet = [&](const MessageElement& p, std::uint32_t n) { packets.push_back(std::string(read_string(p)) + "#" + std::to_string(n)); };
    h.on_ack = [&](std::uint32_t n) { acks.push_back(n); };
    h.on_closed = [&](const RRError&) { ++closed; };

    // Without endpoints the entry is left alone.
    MessageElement packet = make_string_element("x", "to a client");
    MessageEntry theirs = pipe_packet_entry("arm", "p", 4, 1, packet, false, false);
    CHECK_FALSE(ep->take_pipe_elements(theirs));
    CHECK(theirs.elements.size() == 1);

    std::optional<Result<std::uint64_t>> opened;
    ep->open_pipe("arm", "p", false, h, [&](Result<std::uint64_t> r) { opened = r; });
    fake.answer({make_scalar_element<std::int32_t>("index", 7)});
    REQUIRE(opened);
    REQUIRE(opened->ok());
    const std::uint64_t first_id = **opened;

    // One entry with a packet for the gateway's endpoint (7) and one for a client's (4).
    MessageEntry mixed = pipe_packet_entry("arm", "p", 7, 2, make_string_element("x", "ours"), true, false);
    mixed.elements.push_back(std::move(theirs.elements.at(0)));
    CHECK_FALSE(ep->take_pipe_elements(mixed));
    CHECK(packets == std::vector<std::string>{"ours#2"});
    REQUIRE(mixed.elements.size() == 1);
    CHECK(mixed.elements[0].name == "4");  // the client's, for the caller to route
    REQUIRE(fake.sent.size() == 1);         // the ack the device asked for
    CHECK(fake.sent[0].entry_type == MessageEntryType::PipePacketRet);

    MessageEntry only_ours;
    only_ours.entry_type = MessageEntryType::PipePacketRet;
    only_ours.service_path = "arm";
    only_ours.member_name = "p";
    only_ours.elements.push_back(pipe_ack_element(7, 9));
    CHECK(ep->take_pipe_elements(only_ours));
    CHECK(acks == std::vector<std::uint32_t>{9});

    CHECK_FALSE(ep->pipe_closed("arm", "p", 4));  // a client's pipe: not these endpoints'
    CHECK(closed == 0);

    // The shared session drops: the endpoint closes, calls fail with the reason until it is back.
    ep->lost(make_error(MessageErrorType::ConnectionError, "device \"arm\" is not connected"));
    CHECK(closed == 1);
    auto while_down = ep->send_pipe_packet(first_id, make_string_element("x", "a"), false);
    REQUIRE_FALSE(while_down.ok());
    CHECK(while_down.error().message == "device \"arm\" is not connected");
    CHECK_FALSE(ep->pipe_closed("arm", "p", 7));

    ep->resume();
    opened.reset();
    ep->open_pipe("arm", "p", false, h, [&](Result<std::uint64_t> r) { opened = r; });
    fake.answer({make_scalar_element<std::int32_t>("index", 8)});
    REQUIRE(opened);
    REQUIRE(opened->ok());
    CHECK(**opened > first_id);  // ids are not reused across sessions
    auto stale = ep->send_pipe_packet(first_id, make_string_element("x", "a"), false);
    REQUIRE_FALSE(stale.ok());
    CHECK(stale.error().type == MessageErrorType::InvalidArgument);
    CHECK(ep->pipe_closed("arm", "p", 8));
    CHECK(closed == 2);
}
