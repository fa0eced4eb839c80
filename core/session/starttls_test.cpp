#include <catch2/catch.hpp>

#include <string>

#include "base/message/error_entry.hpp"
#include "base/message/message_reader.hpp"
#include "base/message/message_writer.hpp"
#include "core/session/elements.hpp"
#include "core/session/starttls.hpp"

using namespace rr;
using namespace std::chrono_literals;

namespace {

std::vector<std::byte> from_hex(std::string_view hex) {
    std::vector<std::byte> out;
    auto nibble = [](char c) { return c <= '9' ? c - '0' : c - 'a' + 10; };
    for (std::size_t i = 0; i + 1 < hex.size(); i += 2)
        out.push_back(static_cast<std::byte>(nibble(hex[i]) * 16 + nibble(hex[i + 1])));
    return out;
}

std::vector<std::byte> bytes_of(std::span<const std::byte> s) { return {s.begin(), s.end()}; }

// Recorded from the official library (robotraconteur 1.2.9, Python): the first message its client
// writes for rrs+tcp URLs without a node, with `nodeid=12345678-9abc-def0-1234-56789abcdef0`, and
// with `nodename=some.node` (no certificate loaded, so no `mutualauth`); and what its server (NodeID
// b4b9f765-28ed-4660-9da0-7f492dd43da8, NodeName "tlsexp") answered to the first request with a node
// certificate loaded, without one, and to the second (another NodeID).
constexpr std::string_view kOfficialRequestAny =
    "525241435e00000002004000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000"
    "000100000000001e00000001000000000008005354415254544c5300000000000000000000";
constexpr std::string_view kOfficialRequestById =
    "525241435e0000000200400000000000000000000000000000000000123456789abcdef0123456789abcdef00000000000000000000000000000"
    "0100000000001e00000001000000000008005354415254544c5300000000000000000000";
constexpr std::string_view kOfficialRequestByName =
    "5252414367000000020049000000000000000000000000000000000000000000000000000000000000000000000000000000000000000900736f"
    "6d652e6e6f646500000100000000001e00000001000000000008005354415254544c5300000000000000000000";
constexpr std::string_view kOfficialReplyOk =
    "525241436400000002004600b4b9f76528ed46609da07f492dd43da80000000000000000000000000000000000000000000000000600746c7365"
    "7870000000000100000000001e00000002000000000008005354415254544c5300000000000000000000";
constexpr std::string_view kOfficialReplyNoCertificate =
    "52524143d300000002004600b4b9f76528ed46609da07f492dd43da80000000000000000000000000000000000000000000000000600746c7365"
    "7870000000000100000000008d00000002000000000008005354415254544c53000000000100000002003700000009006572726f726e616d65"
    "0b00000000001e000000526f626f745261636f6e746575722e436f6e6e656374696f6e4572726f72380000000b006572726f72737472696e67"
    "0b00000000001d000000536572766572206365727469666963617465206e6f74206c6f61646564";
constexpr std::string_view kOfficialReplyNodeNotFound =
    "52524143c100000002004600b4b9f76528ed46609da07f492dd43da80000000000000000000000000000000000000000000000000600746c7365"
    "7870000000000100000000007b00000002000000000008005354415254544c53000000000700000002003400000009006572726f726e616d65"
    "0b00000000001b000000526f626f745261636f6e746575722e4e6f64654e6f74466f756e64290000000b006572726f72737472696e670b0000"
    "0000000e0000004e6f6465206e6f7420666f756e64";

const NodeID kOfficialServerId = *NodeID::parse("b4b9f765-28ed-4660-9da0-7f492dd43da8");
const NodeID kOtherId = *NodeID::parse("12345678-9abc-def0-1234-56789abcdef0");

StartTlsServerConfig official_like_server(bool certificate = true) {
    return StartTlsServerConfig{kOfficialServerId, "tlsexp", certificate};
}

// Feeds `bytes` to `server` one byte at a time, never more than it asks for while undecided.
void feed_bytewise(StartTlsServer& server, std::span<const std::byte> bytes) {
    for (std::size_t i = 0; i < bytes.size(); ++i) {
        if (server.kind() == FirstMessage::need_more) REQUIRE(server.bytes_wanted() >= 1);
        server.feed(bytes.subspan(i, 1));
    }
}

// Runs a client against a server in memory; returns the client after the reply.
StartTlsClient exchange(StartTlsClientConfig cc, StartTlsServerConfig sc, StartTlsServer* out_server = nullptr) {
    const auto t0 = MonoTime{} + 1s;
    StartTlsClient client(std::move(cc), t0);
    StartTlsServer server(std::move(sc));
    feed_bytewise(server, client.request());
    auto reply = bytes_of(server.reply());
    std::span<const std::byte> rest(reply);
    while (!rest.empty() && client.state() == StartTlsState::waiting) {
        auto n = std::min(rest.size(), client.bytes_wanted());
        client.feed(rest.first(n), t0);
        rest = rest.subspan(n);
    }
    if (out_server) *out_server = std::move(server);
    return client;
}

}  // namespace

TEST_CASE("STARTTLS request: byte for byte what the official client writes", "[starttls]") {
    const auto now = MonoTime{};
    CHECK(bytes_of(StartTlsClient(StartTlsClientConfig{}, now).request()) == from_hex(kOfficialRequestAny));
    CHECK(bytes_of(StartTlsClient(StartTlsClientConfig{kOtherId, "", false}, now).request()) ==
          from_hex(kOfficialRequestById));
    CHECK(bytes_of(StartTlsClient(StartTlsClientConfig{NodeID{}, "some.node", false}, now).request()) ==
          from_hex(kOfficialRequestByName));
}

TEST_CASE("STARTTLS request with a client certificate carries mutualauth \"true\"", "[starttls]") {
    StartTlsClient c(StartTlsClientConfig{NodeID{}, "", true}, MonoTime{});
    auto m = decode_message(SharedBytes::copy_of(c.request()));
    REQUIRE(m);
    REQUIRE(m->entries.size() == 1);
    const auto* e = m->entries.front().find("mutualauth");
    REQUIRE(e);
    CHECK(read_string(*e) == "true");
    CHECK(m->header.sender_node_id.is_any());  // as CORE: the client's NodeID is not sent
}

TEST_CASE("STARTTLS server: replies byte for byte as the official server", "[starttls]") {
    SECTION("accepted") {
        StartTlsServer s(official_like_server());
        feed_bytewise(s, from_hex(kOfficialRequestAny));
        REQUIRE(s.kind() == FirstMessage::start_tls);
        CHECK(bytes_of(s.reply()) == from_hex(kOfficialReplyOk));
        CHECK_FALSE(s.mutual_auth_requested());
        CHECK(s.bytes_wanted() == 0);
    }
    SECTION("no certificate") {
        StartTlsServer s(official_like_server(false));
        s.feed(from_hex(kOfficialRequestAny));
        REQUIRE(s.kind() == FirstMessage::refused);
        CHECK(bytes_of(s.reply()) == from_hex(kOfficialReplyNoCertificate));
        CHECK(s.refusal().type == MessageErrorType::ConnectionError);
    }
    SECTION("another NodeID asked for") {
        StartTlsServer s(official_like_server());
        s.feed(from_hex(kOfficialRequestById));
        REQUIRE(s.kind() == FirstMessage::refused);
        CHECK(bytes_of(s.reply()) == from_hex(kOfficialReplyNodeNotFound));
        CHECK(s.refusal().type == MessageErrorType::NodeNotFound);
    }
    SECTION("another NodeName asked for") {
        StartTlsServer s(official_like_server());
        s.feed(from_hex(kOfficialRequestByName));
        CHECK(s.kind() == FirstMessage::refused);
        CHECK(s.refusal().type == MessageErrorType::NodeNotFound);
    }
}

TEST_CASE("STARTTLS client: reads the official server's replies", "[starttls]") {
    const auto now = MonoTime{};
    SECTION("accepted: the remote NodeID comes from the reply") {
        StartTlsClient c(StartTlsClientConfig{}, now);
        auto reply = from_hex(kOfficialReplyOk);
        CHECK(c.bytes_wanted() == 8);
        c.feed(std::span<const std::byte>(reply).first(8), now);
        CHECK(c.bytes_wanted() == reply.size() - 8);
        c.feed(std::span<const std::byte>(reply).subspan(8), now);
        REQUIRE(c.state() == StartTlsState::done);
        CHECK(c.result().remote_node_id == kOfficialServerId);
        CHECK(c.result().remote_node_name == "tlsexp");
        CHECK_FALSE(c.result().mutual_auth);
        CHECK(c.bytes_wanted() == 0);
    }
    SECTION("no certificate: the server's error") {
        StartTlsClient c(StartTlsClientConfig{}, now);
        c.feed(from_hex(kOfficialReplyNoCertificate), now);
        REQUIRE(c.state() == StartTlsState::failed);
        CHECK(c.error().type == MessageErrorType::ConnectionError);
        CHECK(c.error().message == "Server certificate not loaded");
    }
    SECTION("node not found") {
        StartTlsClient c(StartTlsClientConfig{kOtherId, "", false}, now);
        c.feed(from_hex(kOfficialReplyNodeNotFound), now);
        REQUIRE(c.state() == StartTlsState::failed);
        CHECK(c.error().type == MessageErrorType::NodeNotFound);
    }
    SECTION("a reply from another node than the one asked for") {
        StartTlsClient c(StartTlsClientConfig{kOtherId, "", false}, now);
        c.feed(from_hex(kOfficialReplyOk), now);
        REQUIRE(c.state() == StartTlsState::failed);
        CHECK(c.error().type == MessageErrorType::ConnectionError);
        CHECK_THAT(c.error().message, Catch::Contains("Could not create TLS connection"));
    }
    SECTION("asked by NodeName: the node of that name") {
        StartTlsClient ok(StartTlsClientConfig{NodeID{}, "tlsexp", false}, now);
        ok.feed(from_hex(kOfficialReplyOk), now);
        CHECK(ok.state() == StartTlsState::done);
        StartTlsClient wrong(StartTlsClientConfig{NodeID{}, "other", false}, now);
        wrong.feed(from_hex(kOfficialReplyOk), now);
        CHECK(wrong.state() == StartTlsState::failed);
    }
    SECTION("asked by NodeID: the reply's NodeID must be it") {
        StartTlsClient c(StartTlsClientConfig{kOfficialServerId, "", false}, now);
        c.feed(from_hex(kOfficialReplyOk), now);
        REQUIRE(c.state() == StartTlsState::done);
        CHECK(c.result().remote_node_id == kOfficialServerId);
    }
}

TEST_CASE("STARTTLS client and server in memory", "[starttls]") {
    const NodeID server_id = *NodeID::parse("aaaaaaaa-bbbb-cccc-dddd-eeeeeeeeeeee");
    SECTION("mutual authentication is echoed") {
        StartTlsServer s(StartTlsServerConfig{});
        auto c = exchange(StartTlsClientConfig{NodeID{}, "", true}, StartTlsServerConfig{server_id, "gw", true, true}, &s);
        REQUIRE(c.state() == StartTlsState::done);
        CHECK(c.result().mutual_auth);
        CHECK(s.mutual_auth_requested());
        CHECK(c.result().remote_node_id == server_id);
    }
    SECTION("mutual authentication is not claimed by a server that does not verify client certificates") {
        StartTlsServer s(StartTlsServerConfig{});
        auto c = exchange(StartTlsClientConfig{NodeID{}, "", true}, StartTlsServerConfig{server_id, "gw", true, false}, &s);
        REQUIRE(c.state() == StartTlsState::done);
        CHECK(s.mutual_auth_requested());
        CHECK_FALSE(c.result().mutual_auth);
    }
    SECTION("by NodeID and NodeName together") {
        auto c = exchange(StartTlsClientConfig{server_id, "gw", false}, StartTlsServerConfig{server_id, "gw", true});
        CHECK(c.state() == StartTlsState::done);
        auto d = exchange(StartTlsClientConfig{server_id, "other", false}, StartTlsServerConfig{server_id, "gw", true});
        CHECK(d.state() == StartTlsState::failed);
        CHECK(d.error().type == MessageErrorType::NodeNotFound);
    }
}

TEST_CASE("STARTTLS server: anything else is the ordinary stream protocol's", "[starttls]") {
    SECTION("CreateConnection: plain, every byte kept for replay") {
        StreamConfig cfg;
        cfg.local_node_id = kOtherId;
        StreamConnection client(StreamRole::client, cfg, MonoTime{});
        auto create = bytes_of(client.pending_output());
        StartTlsServer s(official_like_server());
        feed_bytewise(s, create);
        CHECK(s.kind() == FirstMessage::plain);
        CHECK(bytes_of(s.received()) == create);
        CHECK(s.reply().empty());
    }
    SECTION("a first message larger than any STARTTLS: plain after the preamble, nothing more wanted") {
        std::vector<std::byte> pre = from_hex("5252414300000100");  // RRAC, MessageSize 65536
        StartTlsServer s(official_like_server());
        s.feed(pre);
        CHECK(s.kind() == FirstMessage::plain);
        CHECK(s.bytes_wanted() == 0);
        CHECK(s.received().size() == 8);
    }
    SECTION("STARTTLS with bytes after it: plain (a client must wait for the reply)") {
        auto req = from_hex(kOfficialRequestAny);
        req.push_back(std::byte{0x16});
        StartTlsServer s(official_like_server());
        s.feed(req);
        CHECK(s.kind() == FirstMessage::plain);
        CHECK(s.received().size() == req.size());
    }
    SECTION("two entries: plain") {
        Message m;
        MessageEntry e;
        e.entry_type = MessageEntryType::StreamOp;
        e.member_name = "STARTTLS";
        m.entries = {e, e};
        auto bytes = encode_message(m);
        REQUIRE(bytes);
        StartTlsServer s(official_like_server());
        s.feed(std::span<const std::byte>(bytes->data(), bytes->size()));
        CHECK(s.kind() == FirstMessage::plain);
    }
    SECTION("garbage after a good preamble: plain") {
        auto req = from_hex(kOfficialRequestAny);
        for (std::size_t i = 8; i < req.size(); ++i) req[i] = std::byte{0xff};
        StartTlsServer s(official_like_server());
        s.feed(req);
        CHECK(s.kind() == FirstMessage::plain);
    }
    SECTION("not RRAC at all: plain") {
        StartTlsServer s(official_like_server());
        s.feed(from_hex("474554202f20485454"));  // "GET / HTT"
        CHECK(s.kind() == FirstMessage::plain);
    }
}

TEST_CASE("STARTTLS client: timeouts and hostile replies", "[starttls]") {
    const auto t0 = MonoTime{} + 10s;
    SECTION("no answer within the timeout") {
        StartTlsClient c(StartTlsClientConfig{NodeID{}, "", false, 5000ms}, t0);
        REQUIRE(c.next_deadline());
        CHECK(*c.next_deadline() == t0 + 5000ms);
        c.on_timer(t0 + 4999ms);
        CHECK(c.state() == StartTlsState::waiting);
        c.on_timer(t0 + 5000ms);
        REQUIRE(c.state() == StartTlsState::failed);
        CHECK(c.error().type == MessageErrorType::ConnectionError);
        CHECK_FALSE(c.next_deadline());
    }
    SECTION("more bytes than the reply") {
        StartTlsClient c(StartTlsClientConfig{}, t0);
        auto reply = from_hex(kOfficialReplyOk);
        reply.push_back(std::byte{0});
        c.feed(reply, t0);
        REQUIRE(c.state() == StartTlsState::failed);
        CHECK(c.error().type == MessageErrorType::ProtocolError);
    }
    SECTION("bad magic") {
        StartTlsClient c(StartTlsClientConfig{}, t0);
        c.feed(from_hex("485454502f312e31"), t0);  // "HTTP/1.1"
        REQUIRE(c.state() == StartTlsState::failed);
        CHECK(c.error().type == MessageErrorType::ProtocolError);
    }
    SECTION("a reply announcing more than kMaxStartTlsMessageBytes") {
        StartTlsClient c(StartTlsClientConfig{}, t0);
        c.feed(from_hex("5252414300000100"), t0);
        REQUIRE(c.state() == StartTlsState::failed);
        CHECK(c.error().type == MessageErrorType::ProtocolError);
    }
    SECTION("a CreateConnection reply instead of STARTTLS") {
        Message m;
        MessageEntry e;
        e.entry_type = MessageEntryType::StreamOpRet;
        e.member_name = "CreateConnection";
        m.entries.push_back(e);
        auto bytes = encode_message(m);
        REQUIRE(bytes);
        StartTlsClient c(StartTlsClientConfig{}, t0);
        c.feed(std::span<const std::byte>(bytes->data(), bytes->size()), t0);
        REQUIRE(c.state() == StartTlsState::failed);
        CHECK(c.error().type == MessageErrorType::ProtocolError);
    }
}
