#include <catch2/catch.hpp>

#include <fstream>
#include <iterator>

#include "base/message/message_writer.hpp"
#include "base/message/string_table.hpp"
#include "core/session/elements.hpp"
#include "core/session/stream_connection.hpp"
#include "test/support/skip.hpp"

using namespace rr;
using namespace std::chrono_literals;

namespace {

const NodeID kClientId = *NodeID::parse("11111111-2222-3333-4444-555555555555");
const NodeID kServerId = *NodeID::parse("aaaaaaaa-bbbb-cccc-dddd-eeeeeeeeeeee");

StreamConfig client_config() {
    StreamConfig c;
    c.local_node_id = kClientId;
    c.enable_message4 = true;
    c.enable_string_table = true;
    return c;
}

StreamConfig server_config(bool v4 = true) {
    StreamConfig c;
    c.local_node_id = kServerId;
    c.local_node_name = "example.server";
    c.enable_message4 = v4;
    c.heartbeat_period = 12000ms;
    return c;
}

std::vector<std::byte> drain(StreamConnection& s) {
    auto out = s.pending_output();
    std::vector<std::byte> v(out.begin(), out.end());
    s.consume_output(v.size());
    return v;
}

// Moves bytes both ways until neither side has output.
void pump(StreamConnection& a, StreamConnection& b, MonoTime now) {
    for (int i = 0; i < 10; ++i) {
        auto x = drain(a);
        auto y = drain(b);
        if (x.empty() && y.empty()) return;
        if (!x.empty()) (void)b.feed(x, now);
        if (!y.empty()) (void)a.feed(y, now);
    }
}

std::optional<std::vector<std::byte>> read_vector(const char* name) {
    std::ifstream f(rr::test::shared_dir() / "protocol" / "vectors" / name, std::ios::binary);
    if (!f) return std::nullopt;
    std::vector<char> c((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    std::vector<std::byte> out(c.size());
    for (std::size_t i = 0; i < c.size(); ++i) out[i] = static_cast<std::byte>(c[i]);
    return out;
}

// A one-entry member message from the client (endpoint 5) to the server's session (endpoint 9).
Message member_message(MessageEntryType type, std::string member, std::uint32_t request_id) {
    Message m;
    m.header.sender_node_id = kClientId;
    m.header.receiver_node_id = kServerId;
    m.header.sender_endpoint = 5;
    m.header.receiver_endpoint = 9;
    MessageEntry e;
    e.entry_type = type;
    e.service_path = "svc";
    e.member_name = std::move(member);
    e.request_id = request_id;
    m.entries.push_back(std::move(e));
    return m;
}

template <class T>
std::optional<T> next_event(StreamConnection& s) {
    while (auto e = s.poll_event())
        if (auto* v = std::get_if<T>(&*e)) return std::move(*v);
    return std::nullopt;
}

}  // namespace

TEST_CASE("CreateConnection bytes match the documented vectors (wire.md 15.4 a, b)", "[shared]") {
    auto req = read_vector("vec_createconnection_req_v2.bin");
    auto res = read_vector("vec_createconnection_res_v2_only.bin");
    if (!req || !res) RR_SKIP("shared protocol vectors not found under " << rr::test::shared_dir());
    MonoTime t0{};
    StreamConnection client(StreamRole::client, client_config(), t0);
    CHECK(drain(client) == *req);

    StreamConnection server(StreamRole::server, server_config(false), t0);
    REQUIRE(server.feed(*req, t0));
    CHECK(drain(server) == *res);
    auto connected = next_event<StreamConnected>(server);
    REQUIRE(connected);
    CHECK(connected->remote_node_id == kClientId);
    CHECK_FALSE(connected->message4);
    CHECK(connected->connect_combined);
}

TEST_CASE("client and server negotiate message format v4 or v2") {
    for (bool server_v4 : {true, false}) {
        MonoTime t0{};
        StreamConnection client(StreamRole::client, client_config(), t0);
        StreamConnection server(StreamRole::server, server_config(server_v4), t0);
        pump(client, server, t0);
        auto c = next_event<StreamConnected>(client);
        auto s = next_event<StreamConnected>(server);
        REQUIRE(c);
        REQUIRE(s);
        CHECK(c->message4 == server_v4);
        CHECK(s->message4 == server_v4);
        CHECK_FALSE(c->string_table);  // the server (like a stock CORE server) disables string tables
        CHECK(c->connect_combined);
        CHECK(c->remote_node_id == kServerId);
        CHECK(c->remote_node_name == "example.server");
        CHECK(client.send_version() == (server_v4 ? 4 : 2));

        // A member message goes through in the negotiated format and arrives decoded.
        const Message m = member_message(MessageEntryType::PropertyGetReq, "x", 3);
        client.set_session_established(5, 9);
        server.set_session_established(9, 5);
        REQUIRE(client.send(m, t0));
        auto bytes = drain(client);
        CHECK(static_cast<int>(bytes[8]) == (server_v4 ? 4 : 2));
        REQUIRE(server.feed(bytes, t0));
        auto got = next_event<StreamMessage>(server);
        REQUIRE(got);
        CHECK(got->message.entries.at(0).member_name == "x");
        CHECK(got->message.entries.at(0).request_id == 3);
        // v4 routing omission is restored from the connection on receipt.
        CHECK(got->message.header.sender_node_id == kClientId);
        CHECK(got->message.header.sender_endpoint == 5);
        CHECK(got->message.header.receiver_endpoint == 9);
        CHECK(got->frame.size() == bytes.size());
    }
}

TEST_CASE("a server refuses CreateConnection for another node") {
    MonoTime t0{};
    auto cfg = client_config();
    cfg.target_node_name = "other.node";
    StreamConnection client(StreamRole::client, cfg, t0);
    StreamConnection server(StreamRole::server, server_config(), t0);
    pump(client, server, t0);
    auto closed = next_event<StreamClosed>(client);
    REQUIRE(closed);
    CHECK(closed->error.type == MessageErrorType::NodeNotFound);
    CHECK_FALSE(server.is_connected());
}

TEST_CASE("heartbeats keep a connection alive, silence closes it") {
    MonoTime t0{};
    StreamConnection client(StreamRole::client, client_config(), t0);
    StreamConnection server(StreamRole::server, server_config(), t0);
    pump(client, server, t0);
    REQUIRE(client.is_connected());
    REQUIRE(server.is_connected());

    // After 10 s without sending, the client sends ConnectionTest; the server answers.
    auto d = client.next_deadline();
    REQUIRE(d);
    CHECK(*d == t0 + 10s);
    client.on_timer(t0 + 10s);
    auto ping = drain(client);
    REQUIRE_FALSE(ping.empty());
    REQUIRE(server.feed(ping, t0 + 10s));
    auto pong = drain(server);
    REQUIRE_FALSE(pong.empty());
    REQUIRE(client.feed(pong, t0 + 10s));
    CHECK_FALSE(next_event<StreamMessage>(client));  // heartbeats never reach the layer above

    // At 20 s another ConnectionTest, unanswered; nothing received for more than 15 s: closed.
    REQUIRE(client.next_deadline());
    CHECK(*client.next_deadline() == t0 + 20s);
    client.on_timer(t0 + 20s);
    REQUIRE_FALSE(drain(client).empty());
    REQUIRE(client.next_deadline());
    CHECK(*client.next_deadline() == t0 + 25s);
    client.on_timer(t0 + 25s);
    CHECK(client.is_connected());  // 15 s exactly: not more than the timeout yet
    client.on_timer(t0 + 25s + 1ms);
    auto closed = next_event<StreamClosed>(client);
    REQUIRE(closed);
    CHECK(closed->error.type == MessageErrorType::ConnectionError);
    CHECK(client.is_closed());
}

TEST_CASE("a timer that fires late (this process stalled) does not count the stall as the peer's silence") {
    MonoTime t0{};
    StreamConnection client(StreamRole::client, client_config(), t0);
    StreamConnection server(StreamRole::server, server_config(), t0);
    pump(client, server, t0);
    REQUIRE(client.is_connected());
    // Due at 10 s (the heartbeat); the host ran it only at 30 s: 20 s late, more than the 15 s receive
    // timeout. Not closed: the heartbeat goes out and the peer's answer (waiting in the socket) is read.
    REQUIRE(client.next_deadline());
    CHECK(*client.next_deadline() == t0 + 10s);
    client.on_timer(t0 + 30s);
    CHECK(client.is_connected());
    auto ping = drain(client);
    REQUIRE_FALSE(ping.empty());
    REQUIRE(server.feed(ping, t0 + 30s));
    REQUIRE(client.feed(drain(server), t0 + 30s));
    CHECK(client.is_connected());

    // A late timer within the tolerance gets no credit: silent from 30 s, checked at 45 s + 500 ms.
    client.on_timer(t0 + 40s);  // heartbeat due at 40 s, on time
    (void)drain(client);
    REQUIRE(client.next_deadline());
    CHECK(*client.next_deadline() == t0 + 45s);
    client.on_timer(t0 + 45s + 500ms);
    CHECK(client.is_closed());
}

TEST_CASE("a stall is credited once per silence: a peer that stays silent is closed at the next deadline") {
    MonoTime t0{};
    StreamConnection client(StreamRole::client, client_config(), t0);
    StreamConnection server(StreamRole::server, server_config(), t0);
    pump(client, server, t0);
    client.on_timer(t0 + 30s);  // 20 s late: credited, still connected, heartbeat sent
    CHECK(client.is_connected());
    (void)drain(client);
    REQUIRE(client.next_deadline());
    const MonoTime due = *client.next_deadline();
    CHECK(due > t0 + 30s);
    client.on_timer(due + 60s);  // late again, nothing arrived since: no second credit
    CHECK(client.is_closed());
}

TEST_CASE("the liveness probe gets no stall credit: a late timer closes a probed connection without answers") {
    MonoTime t0{};
    StreamConnection client(StreamRole::client, client_config(), t0);
    StreamConnection server(StreamRole::server, server_config(), t0);
    pump(client, server, t0);
    server.set_liveness_probe(500ms, t0 + 1s);
    server.on_timer(t0 + 1s);  // the first probe, on time
    (void)drain(server);
    server.on_timer(t0 + 5s);  // 3.9 s late, no answer since the probe started
    auto closed = next_event<StreamClosed>(server);
    REQUIRE(closed);
    CHECK(closed->error.message.find("liveness probe") != std::string::npos);
}

TEST_CASE("the liveness probe: a ConnectionTest every bound / 5 whatever else is sent, closed without answers") {
    MonoTime t0{};
    StreamConnection client(StreamRole::client, client_config(), t0);
    StreamConnection server(StreamRole::server, server_config(), t0);
    pump(client, server, t0);
    REQUIRE(server.is_connected());
    const MonoTime t1 = t0 + 1s;
    server.set_liveness_probe(500ms, t1);
    // The first probe at once, then every 100 ms; the client answers each.
    MonoTime now = t1;
    for (int i = 0; i < 10; ++i) {
        auto d = server.next_deadline();
        REQUIRE(d);
        CHECK(*d <= now + 100ms);
        now = std::max(now, *d);
        server.on_timer(now);
        auto ping = drain(server);
        REQUIRE_FALSE(ping.empty());
        REQUIRE(client.feed(ping, now));
        auto pong = drain(client);
        REQUIRE_FALSE(pong.empty());
        REQUIRE(server.feed(pong, now + 5ms));
        CHECK(server.is_connected());
    }
    // Busy sending (a wire value each 10 ms) does not hold the probe back.
    const MonoTime t2 = now;
    Message m;
    m.header.sender_node_id = kServerId;
    server.set_session_established(1, 2);
    MessageEntry e;
    e.entry_type = MessageEntryType::EventReq;
    e.service_path = "svc";
    e.member_name = "ev";
    m.entries.push_back(e);
    int probes = 0;
    for (auto t = t2 + 10ms; t <= t2 + 400ms; t += 10ms) {
        REQUIRE(server.send(m, t));
        (void)drain(server);
        if (server.next_deadline() && *server.next_deadline() <= t) {
            server.on_timer(t);
            auto out = drain(server);
            if (!out.empty()) ++probes;
        }
        if (server.is_closed()) break;
    }
    CHECK(probes >= 3);
    // No answer for the bound after the last one: closed, naming the probe.
    server.on_timer(t2 + 5ms + 500ms);
    auto closed = next_event<StreamClosed>(server);
    REQUIRE(closed);
    CHECK(closed->error.type == MessageErrorType::ConnectionError);
    CHECK(closed->error.message.find("liveness probe") != std::string::npos);
}

TEST_CASE("the liveness probe off: the usual heartbeat and receive timeout again") {
    MonoTime t0{};
    StreamConnection client(StreamRole::client, client_config(), t0);
    StreamConnection server(StreamRole::server, server_config(), t0);
    pump(client, server, t0);
    server.set_liveness_probe(500ms, t0);
    server.set_liveness_probe(std::nullopt, t0 + 100ms);
    server.on_timer(t0 + 5s);
    CHECK(server.is_connected());
    CHECK(drain(server).empty());  // no probe, no heartbeat before 12 s
    REQUIRE(server.next_deadline());
    CHECK(*server.next_deadline() == t0 + 12s);
}

TEST_CASE("an unanswered CreateConnection times out") {
    MonoTime t0{};
    StreamConnection client(StreamRole::client, client_config(), t0);
    (void)drain(client);
    client.on_timer(t0 + 11s);
    CHECK(client.is_closed());
}

TEST_CASE("a member message before CreateConnection closes the server side") {
    MonoTime t0{};
    StreamConnection server(StreamRole::server, server_config(), t0);
    Message m;
    m.header.sender_node_id = kClientId;
    MessageEntry e;
    e.entry_type = MessageEntryType::PropertyGetReq;
    e.service_path = "svc";
    m.entries.push_back(e);
    std::vector<std::byte> bytes;
    REQUIRE(encode_message(m, bytes));
    CHECK_FALSE(server.feed(bytes, t0));
    CHECK(server.is_closed());
}

TEST_CASE("the pre-session limit applies until the client session exists") {
    MonoTime t0{};
    StreamConnection client(StreamRole::client, client_config(), t0);
    StreamConnection server(StreamRole::server, server_config(), t0);
    pump(client, server, t0);
    Message m;
    MessageEntry e;
    e.entry_type = MessageEntryType::FunctionCallReq;
    std::vector<double> big(600 * 1024 / 8);
    e.elements.push_back(make_array_element("d", std::span<const double>(big)));
    m.entries.push_back(e);
    auto r = client.send(m, t0);
    REQUIRE_FALSE(r);
    CHECK(r.error().type == MessageErrorType::BufferLimitViolation);
    client.set_session_established(1, 2);
    CHECK(client.send(m, t0));
}

TEST_CASE("StreamCheckCapability is answered as CORE does") {
    MonoTime t0{};
    StreamConnection client(StreamRole::client, client_config(), t0);
    StreamConnection server(StreamRole::server, server_config(), t0);
    pump(client, server, t0);
    Message m;
    m.header.sender_node_id = kClientId;
    MessageEntry e;
    e.entry_type = MessageEntryType::StreamCheckCapability;
    e.member_name = "com.robotraconteur.message.v4";
    m.entries.push_back(e);
    std::vector<std::byte> bytes;
    REQUIRE(encode_message(m, bytes));
    REQUIRE(server.feed(bytes, t0));
    auto reply = drain(server);
    REQUIRE(client.feed(reply, t0));
    // StreamCheckCapabilityRet is transport-internal: it is consumed, not delivered.
    CHECK_FALSE(next_event<StreamMessage>(client));
    CHECK(client.is_connected());
}

TEST_CASE("a connection reuses the entry vectors of the messages it sends and receives") {
    MonoTime t0{};
    StreamConnection client(StreamRole::client, client_config(), t0);
    StreamConnection server(StreamRole::server, server_config(), t0);
    pump(client, server, t0);
    client.set_session_established(5, 9);
    server.set_session_established(9, 5);
    auto message = [](std::uint32_t request_id) { return member_message(MessageEntryType::FunctionCallReq, "f", request_id); };

    // A message given up to send(): its entry vector is kept once it is encoded.
    Message first = message(1);
    const MessageEntry* storage = first.entries.data();
    const std::size_t kept = client.entry_vectors().size();  // the handshake's reply left one too
    REQUIRE(client.send(std::move(first), t0));
    CHECK(first.entries.empty());
    CHECK(client.entry_vectors().size() == kept + 1);

    // The next message built with a kept vector uses that storage, and still arrives whole.
    Message second = message(2);
    second.entries = client.entry_vectors().take();
    CHECK(second.entries.data() == storage);
    second.entries.push_back(message(2).entries.front());
    REQUIRE(client.send(std::move(second), t0));
    REQUIRE(server.feed(drain(client), t0));
    std::vector<std::uint32_t> ids;
    while (auto got = next_event<StreamMessage>(server)) {
        REQUIRE(got->message.entries.size() == 1);
        ids.push_back(got->message.entries.front().request_id);
        // Handed back after handling: the next received message is decoded into it.
        server.entry_vectors().give(std::move(got->message.entries));
    }
    CHECK(ids == std::vector<std::uint32_t>{1, 2});
    CHECK(server.entry_vectors().size() == 2);
}

TEST_CASE("a large payload leaves a connection spliced into its output and arrives intact") {
    MonoTime t0{};
    StreamConnection client(StreamRole::client, client_config(), t0);
    StreamConnection server(StreamRole::server, server_config(), t0);
    pump(client, server, t0);
    REQUIRE(client.is_connected());
    (void)next_event<StreamConnected>(server);
    std::vector<double> values(25'000);
    for (std::size_t i = 0; i < values.size(); ++i) values[i] = 0.5 * static_cast<double>(i);
    Message m = member_message(MessageEntryType::FunctionCallReq, "Echo", 3);
    m.entries[0].elements.push_back(make_array_element("d", std::span<const double>(values)));
    const SharedBytes payload = m.entries[0].elements[0].data;
    REQUIRE(client.send(m, t0));
    CHECK(client.pending_output_size() > payload.size());

    // Gathered: the payload is not copied, the pieces carry it in place.
    GatherBuffer out;
    client.take_output(out);
    CHECK(client.pending_output_size() == 0);
    REQUIRE(out.splices().size() == 1);
    CHECK(out.splices()[0].bytes.data() == payload.data());
    out.for_each_piece([&](std::span<const std::byte> piece) { REQUIRE(server.feed(piece, t0)); });
    auto got = next_event<StreamMessage>(server);
    REQUIRE(got);
    CHECK(got->message.entries == m.entries);

    // Contiguous (pending_output, as the wasm client writes): the same bytes, the splice copied in.
    REQUIRE(client.send(m, t0));
    const auto flat = drain(client);
    std::vector<std::byte> gathered;
    out.for_each_piece([&](std::span<const std::byte> piece) { gathered.insert(gathered.end(), piece.begin(), piece.end()); });
    CHECK(flat == gathered);
    REQUIRE(server.feed(flat, t0));
    got = next_event<StreamMessage>(server);
    REQUIRE(got);
    CHECK(got->message.entries == m.entries);

    // A large encoded entry held by a shared_ptr is spliced, not copied, into each message.
    MessageEntry wire;
    wire.entry_type = MessageEntryType::WirePacket;
    wire.service_path = "svc";
    wire.member_name = "frames";
    wire.elements.push_back(make_array_element("value", std::span<const double>(values)));
    auto entry = std::make_shared<const EncodedEntry>(wire);
    Message header;
    header.header.sender_node_id = kServerId;
    header.header.receiver_node_id = kClientId;
    REQUIRE(server.send(Message(header), *entry, t0));
    REQUIRE(server.send(Message(header), *entry, t0));
    GatherBuffer fan_out;
    server.take_output(fan_out);
    REQUIRE(fan_out.splices().size() == 2);
    CHECK(fan_out.splices()[0].bytes.data() == fan_out.splices()[1].bytes.data());
    const auto before = client.pending_output_size();
    fan_out.for_each_piece([&](std::span<const std::byte> piece) { REQUIRE(client.feed(piece, t0)); });
    CHECK(client.pending_output_size() == before);
    for (int i = 0; i < 2; ++i) {
        got = next_event<StreamMessage>(client);
        REQUIRE(got);
        REQUIRE(got->message.entries.size() == 1);
        CHECK(got->message.entries[0] == wire);
    }
}

TEST_CASE("entries from a peer that uses string-table codes can be sent on another connection (wire.md 2.6)") {
    MonoTime t0{};
    // Upstream: a device that leaves the string table on (as the official TcpTransport can): both
    // sides negotiate it, and the device sends names as standard and message-local codes.
    StreamConfig device_config = server_config();
    device_config.enable_string_table = true;
    StreamConnection upstream(StreamRole::client, client_config(), t0);
    StreamConnection device(StreamRole::server, device_config, t0);
    pump(upstream, device, t0);
    auto negotiated = next_event<StreamConnected>(upstream);
    REQUIRE(negotiated);
    CHECK(negotiated->string_table);
    upstream.set_session_established(5, 9);
    device.set_session_established(9, 5);

    Message event;
    event.header.sender_node_id = kServerId;
    event.header.receiver_node_id = kClientId;
    event.header.sender_endpoint = 9;
    event.header.receiver_endpoint = 5;
    MessageEntry e;
    e.entry_type = MessageEntryType::EventReq;
    e.service_path = "svc.child";
    e.member_name = "thenable";
    MessageElement value = make_array_element("value", std::span<const double>(std::vector<double>{1.5}));
    MessageElement s;
    s.name = "point";
    s.type = DataTypes::structure_t;
    s.type_name = "experimental.demo.Point";
    s.elements.push_back(make_array_element("x", std::span<const double>(std::vector<double>{2.5})));
    e.elements.push_back(value);
    e.elements.push_back(s);
    event.entries.push_back(e);
    Message coded = event;
    apply_string_table(coded, StringTableOptions{});
    REQUIRE(coded.entries[0].member_name_code);
    REQUIRE_FALSE(coded.header.string_table.empty());
    REQUIRE(device.send(coded, t0));
    REQUIRE(upstream.feed(drain(device), t0));
    auto got = next_event<StreamMessage>(upstream);
    REQUIRE(got);
    REQUIRE(got->message.entries.size() == 1);
    const MessageEntry& received = got->message.entries[0];
    CHECK(received.member_name == "thenable");
    CHECK(received.service_path == "svc.child");
    CHECK_FALSE(received.member_name_code);
    CHECK_FALSE(received.service_path_code);
    CHECK_FALSE(received.elements[1].type_name_code);
    CHECK(got->message.header.string_table.empty());
    CHECK(received.elements == e.elements);

    // Downstream: a client of ours (a stock server side: no string table) gets the entry re-addressed.
    StreamConnection downstream(StreamRole::server, server_config(), t0);
    StreamConnection browser(StreamRole::client, client_config(), t0);
    pump(browser, downstream, t0);
    REQUIRE(downstream.is_connected());
    downstream.set_session_established(9, 5);
    browser.set_session_established(5, 9);
    Message forward;
    forward.header.sender_node_id = kServerId;
    forward.header.receiver_node_id = kClientId;
    forward.header.sender_endpoint = 9;
    forward.header.receiver_endpoint = 5;
    forward.entries.push_back(received);
    forward.entries[0].service_path = "gateway.child";
    REQUIRE(downstream.send(forward, t0));
    // Fanned out as one encoded entry as well.
    Message header = forward;
    header.entries.clear();
    EncodedEntry shared(received);
    REQUIRE(downstream.send(std::move(header), shared, t0));
    REQUIRE(browser.feed(drain(downstream), t0));
    auto first = next_event<StreamMessage>(browser);
    auto second = next_event<StreamMessage>(browser);
    REQUIRE(first);
    REQUIRE(second);
    CHECK(first->message.entries.at(0).service_path == "gateway.child");
    CHECK(first->message.entries.at(0).member_name == "thenable");
    CHECK(first->message.entries.at(0).elements == e.elements);
    CHECK(second->message.entries.at(0).service_path == "svc.child");
    CHECK(second->message.entries.at(0).elements == e.elements);
}
