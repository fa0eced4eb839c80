#include <catch2/catch.hpp>

#include "core/session/client_session.hpp"
#include "core/session/elements.hpp"

using namespace rr;
using namespace std::chrono_literals;

namespace {

const NodeID kClientId = *NodeID::parse("11111111-2222-3333-4444-555555555555");
const NodeID kServerId = *NodeID::parse("aaaaaaaa-bbbb-cccc-dddd-eeeeeeeeeeee");
constexpr std::uint32_t kServiceEndpoint = 777;

// A scripted service side: a server StreamConnection plus hand-written answers.
struct ScriptedServer {
    StreamConnection stream;
    bool combined;
    std::vector<MessageEntry> received;
    std::optional<RRError> refuse_connect;  // answer the connect with this error
    bool silent = false;                    // answer no entry at all (CreateConnection still is)

    ScriptedServer(MonoTime t0, bool allow_combined)
        : stream(StreamRole::server, [] {
              StreamConfig c;
              c.local_node_id = kServerId;
              c.local_node_name = "scripted";
              return c;
          }(), t0),
          combined(allow_combined) {}

    void reply(const MessageHeader& h, MessageEntry r, MonoTime now) {
        Message m;
        m.header.sender_node_id = kServerId;
        m.header.receiver_node_id = h.sender_node_id;
        m.header.sender_endpoint = kServiceEndpoint;
        m.header.receiver_endpoint = h.sender_endpoint;
        m.entries.push_back(std::move(r));
        REQUIRE(stream.send(m, now));
    }

    void handle(MonoTime now) {
        while (auto ev = stream.poll_event()) {
            auto* sm = std::get_if<StreamMessage>(&*ev);
            if (!sm) continue;
            for (auto& e : sm->message.entries) {
                received.push_back(e);
                if (silent) continue;
                MessageEntry r;
                r.entry_type = static_cast<MessageEntryType>(static_cast<std::uint16_t>(e.entry_type) + 1);
                r.service_path = e.service_path;
                r.member_name = e.member_name;
                r.request_id = e.request_id;
                switch (e.entry_type) {
                    case MessageEntryType::ConnectClientCombined:
                        if (refuse_connect) {
                            set_entry_error(r, *refuse_connect);
                            break;
                        }
                        if (!combined) {
                            set_entry_error(r, make_error(MessageErrorType::ProtocolError, "Invalid Special Operation"));
                            break;
                        }
                        r.elements.push_back(make_string_element("objecttype", "example.s.Obj"));
                        {
                            MessageElement defs;
                            defs.name = "servicedefs";
                            defs.type = DataTypes::list_t;
                            auto d0 = make_string_element("", "service example.s\nimport example.base\nobject Obj\nend\n");
                            d0.number = 0;
                            auto d1 = make_string_element("", "service example.base\n");
                            d1.number = 1;
                            defs.elements.push_back(d0);
                            defs.elements.push_back(d1);
                            r.elements.push_back(defs);
                        }
                        break;
                    case MessageEntryType::GetServiceDesc:
                        if (const auto* t = e.find("ServiceType"))
                            r.elements.push_back(make_string_element("servicedef", "service " + std::string(read_string(*t)) + "\n"));
                        else
                            r.elements.push_back(make_string_element("servicedef", "service example.s\n\nimport example.base\n\nobject Obj\nend\n"));
                        break;
                    case MessageEntryType::ObjectTypeName:
                        r.elements.push_back(make_string_element("objecttype", "example.s.Obj"));
                        break;
                    case MessageEntryType::ConnectClient:
                    case MessageEntryType::DisconnectClient:
                    case MessageEntryType::ClientKeepAliveReq: break;
                    case MessageEntryType::PropertyGetReq:
                        if (e.member_name == "slow") continue;  // never answered: the client times out
                        r.elements.push_back(make_scalar_element("value", 1.5));
                        break;
                    default: continue;
                }
                reply(sm->message.header, std::move(r), now);
                if (e.entry_type == MessageEntryType::ConnectClientCombined ||
                    e.entry_type == MessageEntryType::ConnectClient)
                    stream.set_session_established(kServiceEndpoint, sm->message.header.sender_endpoint);
            }
        }
    }
};

void pump(ClientSession& c, ScriptedServer& s, MonoTime now) {
    for (int i = 0; i < 20; ++i) {
        auto a = c.pending_output();
        std::vector<std::byte> x(a.begin(), a.end());
        c.consume_output(x.size());
        if (!x.empty()) (void)s.stream.feed(x, now);
        s.handle(now);
        auto b = s.stream.pending_output();
        std::vector<std::byte> y(b.begin(), b.end());
        s.stream.consume_output(y.size());
        if (!y.empty()) (void)c.feed(y, now);
        if (x.empty() && y.empty()) return;
    }
}

ClientSessionConfig config() {
    ClientSessionConfig c;
    c.stream.local_node_id = kClientId;
    c.service_name = "svc";
    c.local_endpoint = 4242;
    return c;
}

template <class T>
std::optional<T> next_event(ClientSession& s) {
    while (auto e = s.poll_event())
        if (auto* v = std::get_if<T>(&*e)) return std::move(*v);
    return std::nullopt;
}

}  // namespace

TEST_CASE("client session connects with ConnectClientCombined") {
    MonoTime t0{};
    ClientSession c(config(), t0);
    ScriptedServer s(t0, true);
    pump(c, s, t0);
    REQUIRE(c.is_connected());
    auto connected = next_event<ClientSessionConnected>(c);
    REQUIRE(connected);
    CHECK(connected->info.object_type == "example.s.Obj");
    CHECK(connected->info.service_definitions.size() == 2);
    CHECK(c.remote_endpoint() == kServiceEndpoint);
    REQUIRE_FALSE(s.received.empty());
    const auto& req = s.received.front();
    CHECK(req.entry_type == MessageEntryType::ConnectClientCombined);
    CHECK(req.service_path == "svc");
    REQUIRE(req.find("clientversion"));
    CHECK(read_string(*req.find("returnservicedefs")) == "true");
}

TEST_CASE("client session fails cleanly when the combined connect is refused") {
    MonoTime t0{};
    ClientSession c(config(), t0);
    ScriptedServer s(t0, false);
    pump(c, s, t0);
    auto closed = next_event<ClientSessionClosed>(c);
    REQUIRE(closed);
    CHECK(closed->error.type == MessageErrorType::ProtocolError);
    CHECK(c.is_closed());
}

TEST_CASE("an unknown service is reported by name under the standard error name") {
    MonoTime t0{};
    ClientSession c(config(), t0);
    ScriptedServer s(t0, true);
    // What CORE answers (RobotRaconteurNode.cpp, ConnectClient): a non-canonical name, no service name.
    RRError core_answer = make_error(MessageErrorType::ServiceNotFound, "Service not found");
    core_answer.name = "RobotRaconteur.ServiceNotFoundException";
    s.refuse_connect = core_answer;
    pump(c, s, t0);
    auto closed = next_event<ClientSessionClosed>(c);
    REQUIRE(closed);
    CHECK(closed->error.type == MessageErrorType::ServiceNotFound);
    CHECK(closed->error.name == "RobotRaconteur.ServiceNotFound");
    CHECK(closed->error.message == "service \"svc\" not found");
    // Another node's own wording is kept when it adds something.
    CHECK(service_not_found_error("svc", "node is shutting down").message ==
          "service \"svc\" not found (node is shutting down)");
    CHECK(service_not_found_error("svc", "Service \"svc\" not found").message == "service \"svc\" not found");
}

TEST_CASE("connect_timeout bounds the whole connect, from construction") {
    auto cfg = config();
    cfg.connect_timeout = 2500ms;
    cfg.request_timeout = 15s;  // longer than the bound: the bound must win

    SECTION("a peer that accepted the connection and never answers CreateConnection") {
        MonoTime t0{};
        ClientSession c(cfg, t0);
        CHECK(c.next_deadline() == t0 + 2500ms);
        c.on_timer(t0 + 2499ms);
        CHECK_FALSE(c.is_closed());
        c.on_timer(t0 + 2500ms);
        REQUIRE(c.is_closed());
        auto closed = next_event<ClientSessionClosed>(c);
        REQUIRE(closed);
        CHECK(closed->error.type == MessageErrorType::ConnectionError);
        CHECK(closed->error.message == "connect timed out after 2.5 s: the peer did not answer CreateConnection");
    }
    SECTION("a node that negotiates the stream but never answers the service connect") {
        MonoTime t0{};
        ClientSession c(cfg, t0);
        ScriptedServer s(t0, true);
        s.silent = true;
        pump(c, s, t0 + 1s);  // CreateConnection answered at 1 s; ConnectClientCombined never
        REQUIRE_FALSE(c.is_closed());
        CHECK(c.next_deadline() == t0 + 2500ms);
        c.on_timer(t0 + 2500ms);
        auto closed = next_event<ClientSessionClosed>(c);
        REQUIRE(closed);
        CHECK(closed->error.type == MessageErrorType::ConnectionError);
        CHECK(closed->error.message == "connect timed out after 2.5 s: the service did not answer the connect request");
    }
    SECTION("no effect once connected") {
        MonoTime t0{};
        ClientSession c(cfg, t0);
        ScriptedServer s(t0, true);
        pump(c, s, t0);
        REQUIRE(c.is_connected());
        c.on_timer(t0 + 3s);
        CHECK(c.is_connected());
    }
    CHECK(seconds_text(2000ms) == "2 s");
    CHECK(seconds_text(250ms) == "0.25 s");
}

TEST_CASE("requests are matched by RequestID and time out after 15 s") {
    MonoTime t0{};
    ClientSession c(config(), t0);
    ScriptedServer s(t0, true);
    pump(c, s, t0);
    REQUIRE(c.is_connected());
    (void)next_event<ClientSessionConnected>(c);

    MessageEntry get;
    get.entry_type = MessageEntryType::PropertyGetReq;
    get.service_path = "svc";
    get.member_name = "x";
    auto id = c.request(MessageEntry(get), t0);
    REQUIRE(id);
    get.member_name = "slow";
    auto slow = c.request(MessageEntry(get), t0);
    REQUIRE(slow);
    CHECK(*slow == *id + 1);
    pump(c, s, t0);
    auto r = next_event<ClientResponse>(c);
    REQUIRE(r);
    CHECK(r->request_id == *id);
    REQUIRE(r->entry);
    double v = 0;
    CHECK(read_scalar(*r->entry->find("value"), v));
    CHECK(v == 1.5);

    // Keep the transport alive with a heartbeat exchange, then let the request deadline pass.
    s.stream.on_timer(t0 + 12s);
    pump(c, s, t0 + 12s);
    c.on_timer(t0 + 16s);
    CHECK(c.is_connected());
    auto timeout = next_event<ClientResponse>(c);
    REQUIRE(timeout);
    CHECK(timeout->request_id == *slow);
    REQUIRE_FALSE(timeout->entry);
    CHECK(timeout->entry.error().type == MessageErrorType::RequestTimeout);
}

TEST_CASE("keep-alive after 60 s idle and disconnect") {
    MonoTime t0{};
    ClientSession c(config(), t0);
    ScriptedServer s(t0, true);
    pump(c, s, t0);
    REQUIRE(c.is_connected());
    // Keep the stream alive: feed heartbeats both ways every 10 s up to 60 s.
    for (int t = 10; t <= 60; t += 10) {
        c.on_timer(t0 + std::chrono::seconds(t));
        s.stream.on_timer(t0 + std::chrono::seconds(t));
        pump(c, s, t0 + std::chrono::seconds(t));
    }
    bool keepalive = false;
    for (const auto& e : s.received) keepalive |= e.entry_type == MessageEntryType::ClientKeepAliveReq;
    CHECK(keepalive);
    c.disconnect(t0 + 61s);
    pump(c, s, t0 + 61s);
    CHECK(c.is_closed());
    CHECK(s.received.back().entry_type == MessageEntryType::DisconnectClient);
}
