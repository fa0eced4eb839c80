// ServiceSession fed by core's own ClientSession in memory: bytes are moved by hand and time is moved
// by hand, no sockets and no clocks.
#include <catch2/catch.hpp>

#include <set>

#include "base/message/error_entry.hpp"
#include "core/session/client_session.hpp"
#include "core/session/elements.hpp"
#include "core/session/service_session.hpp"

using namespace rr;
using namespace std::chrono_literals;

namespace {

const NodeID kClientId = *NodeID::parse("11111111-2222-3333-4444-555555555555");
const NodeID kServiceNodeId = *NodeID::parse("aaaaaaaa-bbbb-cccc-dddd-eeeeeeeeeeee");

struct FakeService : HostedService {
    std::string name_ = "svc";
    bool auth = false;
    const std::string& name() const override { return name_; }
    std::vector<std::string> service_definitions() const override {
        return {"service example.svc\nimport example.base\nobject Obj\nend\n", "service example.base\n"};
    }
    std::optional<std::string> service_definition(std::string_view type) const override {
        if (type == "example.base") return std::string("service example.base\n");
        return std::nullopt;
    }
    ObjectTypeInfo root_type() const override { return {"example.svc.Obj", {"example.base.Thing"}}; }
    bool requires_authentication() const override { return auth; }
    bool handles_locks() const override { return locks; }
    bool admits_sessions() const override { return admits; }
    bool locks = false;
    bool admits = false;
    Result<void> authenticate(const std::string& user, const MessageElement* creds) override {
        const MessageElement* pw = creds ? creds->find("password") : nullptr;
        if (user == "alice" && pw && read_string(*pw) == "secret") return {};
        return fail(MessageErrorType::AuthenticationError, "Invalid username or password");
    }
};

struct FakeHost : ServiceHost {
    std::shared_ptr<FakeService> service = std::make_shared<FakeService>();
    std::uint32_t next = 100;
    std::set<std::uint32_t> live;
    std::shared_ptr<HostedService> hosted_service(std::string_view name) const override {
        return name == "svc" ? service : nullptr;
    }
    std::uint32_t allocate_endpoint() override {
        live.insert(next);
        return next++;
    }
    void release_endpoint(std::uint32_t e) override { live.erase(e); }
};

struct Pair {
    MonoTime now{};
    FakeHost host;
    ServiceSession service;
    ClientSession client;
    std::vector<ServiceSessionEvent> service_events;
    std::vector<ClientSessionEvent> client_events;

    static ServiceSessionConfig service_config() {
        ServiceSessionConfig c;
        c.stream.local_node_id = kServiceNodeId;
        c.stream.local_node_name = "example.node";
        c.callback_timeout = 2s;
        c.wire_hold_bytes = 1024;
        return c;
    }
    static ClientSessionConfig client_config(std::string service, std::string user = {}, std::string password = {}) {
        ClientSessionConfig c;
        c.stream.local_node_id = kClientId;
        c.service_name = std::move(service);
        c.username = std::move(user);
        c.password = std::move(password);
        c.local_endpoint = 42;
        return c;
    }

    explicit Pair(std::string service_name = "svc", bool auth = false, std::string user = {}, std::string password = {})
        : service(host, service_config(), now), client(client_config(std::move(service_name), std::move(user), std::move(password)), now) {
        host.service->auth = auth;
    }

    // Moves bytes both ways until nothing is left, collecting events.
    void pump() {
        std::vector<std::byte> buf;
        for (int i = 0; i < 100; ++i) {
            bool moved = false;
            if (client.pending_output_size()) {
                client.take_output(buf);
                service.feed(buf, now);
                moved = true;
            }
            if (service.pending_output_size()) {
                service.take_output(buf);
                (void)client.feed(buf, now);
                moved = true;
            }
            while (auto e = service.poll_event()) service_events.push_back(std::move(*e));
            while (auto e = client.poll_event()) client_events.push_back(std::move(*e));
            if (!moved) return;
        }
        FAIL("pump did not settle");
    }

    template <class T>
    std::vector<T> take(std::vector<ServiceSessionEvent>& from) {
        std::vector<T> out;
        for (auto it = from.begin(); it != from.end();) {
            if (auto* t = std::get_if<T>(&*it)) {
                out.push_back(std::move(*t));
                it = from.erase(it);
            } else {
                ++it;
            }
        }
        return out;
    }
    template <class T>
    std::vector<T> take_client() {
        std::vector<T> out;
        for (auto it = client_events.begin(); it != client_events.end();) {
            if (auto* t = std::get_if<T>(&*it)) {
                out.push_back(std::move(*t));
                it = client_events.erase(it);
            } else {
                ++it;
            }
        }
        return out;
    }

    void connect() {
        pump();
        REQUIRE(take_client<ClientSessionConnected>().size() == 1);
        REQUIRE(take<ServiceSessionOpened>(service_events).size() == 1);
    }
};

MessageEntry member_request(std::string member, MessageEntryType type = MessageEntryType::PropertyGetReq) {
    MessageEntry e;
    e.entry_type = type;
    e.service_path = "svc";
    e.member_name = std::move(member);
    return e;
}


}  // namespace

TEST_CASE("service session: a client connects, the session opens with the service's types and definitions") {
    Pair p;
    p.pump();
    auto connected = p.take_client<ClientSessionConnected>();
    REQUIRE(connected.size() == 1);
    CHECK(connected[0].info.object_type == "example.svc.Obj");
    CHECK(connected[0].info.object_implements == std::vector<std::string>{"example.base.Thing"});
    CHECK(connected[0].info.service_definitions.size() == 2);
    auto opened = p.take<ServiceSessionOpened>(p.service_events);
    REQUIRE(opened.size() == 1);
    CHECK(opened[0].service == p.host.service);
    CHECK(opened[0].client_endpoint == 42);
    CHECK(p.service.endpoint() == opened[0].endpoint);
    CHECK(p.host.live.count(opened[0].endpoint) == 1);
    CHECK(p.client.remote_endpoint() == opened[0].endpoint);
}

TEST_CASE("service session: member requests go to the host in order and the replies reach the client") {
    Pair p;
    p.connect();
    auto id1 = p.client.request(member_request("a"), p.now);
    auto id2 = p.client.request(member_request("b", MessageEntryType::FunctionCallReq), p.now);
    REQUIRE(id1);
    REQUIRE(id2);
    p.pump();
    auto requests = p.take<ServiceRequest>(p.service_events);
    REQUIRE(requests.size() == 2);
    CHECK(requests[0].entry().member_name == "a");
    CHECK(requests[1].entry().member_name == "b");
    CHECK(requests[0].needs_reply);
    // Answer the second first: each reply finds its request by RequestID.
    MessageEntry r2 = reply_to(requests[1].entry());
    r2.elements.push_back(make_scalar_element<std::int32_t>("return", 7));
    p.service.reply(std::move(r2), p.now);
    p.service.reply(reply_to(requests[0].entry()), p.now);
    p.pump();
    auto responses = p.take_client<ClientResponse>();
    REQUIRE(responses.size() == 2);
    CHECK(responses[0].request_id == *id2);
    REQUIRE(responses[0].entry);
    std::int32_t v = 0;
    REQUIRE(responses[0].entry->find("return"));
    CHECK(read_scalar(*responses[0].entry->find("return"), v));
    CHECK(v == 7);
    CHECK(responses[1].request_id == *id1);
}

TEST_CASE("service session: a lone request travels in its message's entry vector, recycled for the next message, "
          "and a sent reply's element vector comes back with the next request") {
    Pair p;
    p.connect();
    REQUIRE(p.client.request(member_request("a"), p.now));
    p.pump();
    auto first = p.take<ServiceRequest>(p.service_events);
    REQUIRE(first.size() == 1);
    REQUIRE(first[0].entries.size() == 1);
    const MessageEntry* slot = first[0].entries.data();
    MessageEntry r = reply_to(first[0].entry());
    // Built in the request's element vector, as the service does (service_object.cpp, reply_in).
    r.elements = std::move(first[0].entry().elements);
    r.elements.clear();
    r.elements.push_back(make_scalar_element<std::int32_t>("return", 1));
    const MessageElement* reply_elements = r.elements.data();
    p.service.reply(std::move(r), p.now);
    p.service.recycle(std::move(first[0]));
    CHECK(first[0].entries.empty());
    p.pump();
    auto answered = p.take_client<ClientResponse>();
    REQUIRE(answered.size() == 1);
    REQUIRE(answered[0].entry);
    std::int32_t v = 0;
    REQUIRE(answered[0].entry->find("return"));
    CHECK(read_scalar(*answered[0].entry->find("return"), v));
    CHECK(v == 1);

    REQUIRE(p.client.request(member_request("b"), p.now));
    p.pump();
    auto second = p.take<ServiceRequest>(p.service_events);
    REQUIRE(second.size() == 1);
    CHECK(second[0].entry().member_name == "b");
    CHECK(second[0].entries.data() == slot);                           // decoded into the recycled vector
    CHECK(second[0].entry().elements.data() == reply_elements);        // room for its reply: the last reply's
    CHECK(second[0].entry().elements.empty());
}

TEST_CASE("service session: a reply over the size limit becomes an error reply with the same RequestID") {
    Pair p;
    p.connect();
    auto id = p.client.request(member_request("big"), p.now);
    REQUIRE(id);
    p.pump();
    auto requests = p.take<ServiceRequest>(p.service_events);
    REQUIRE(requests.size() == 1);
    MessageEntry r = reply_to(requests[0].entry());
    std::vector<std::uint8_t> huge(13u * 1024u * 1024u);
    r.elements.push_back(make_array_element<std::uint8_t>("return", huge));
    const auto reply_type = r.entry_type;
    const auto service_path = r.service_path;
    p.service.reply(std::move(r), p.now);
    p.pump();
    auto responses = p.take_client<ClientResponse>();
    REQUIRE(responses.size() == 1);
    CHECK(responses[0].request_id == *id);
    REQUIRE(responses[0].entry);
    CHECK(responses[0].entry->error == MessageErrorType::BufferLimitViolation);
    CHECK(responses[0].entry->entry_type == reply_type);
    CHECK(responses[0].entry->member_name == "big");
    CHECK(responses[0].entry->service_path == service_path);
    CHECK(responses[0].entry->elements.size() == 2);  // errorname and errorstring only: the payload is gone
}

TEST_CASE("service session: an unknown service is refused with a ServiceNotFound naming it") {
    Pair p("nosuch");
    p.pump();
    auto closed = p.take_client<ClientSessionClosed>();
    REQUIRE(closed.size() == 1);
    CHECK(closed[0].error.type == MessageErrorType::ServiceNotFound);
    CHECK(closed[0].error.message.find("nosuch") != std::string::npos);
    CHECK(p.take<ServiceSessionOpened>(p.service_events).empty());
    CHECK(p.host.live.empty());
}

TEST_CASE("service session: login with the connect, wrong password refused, logout blocks member requests") {
    SECTION("wrong password") {
        Pair p("svc", true, "alice", "nope");
        p.pump();
        auto closed = p.take_client<ClientSessionClosed>();
        REQUIRE(closed.size() == 1);
        CHECK(closed[0].error.type == MessageErrorType::AuthenticationError);
        CHECK(p.take<ServiceSessionOpened>(p.service_events).empty());
    }
    SECTION("right password, then logout") {
        Pair p("svc", true, "alice", "secret");
        p.pump();
        REQUIRE(p.take_client<ClientSessionConnected>().size() == 1);
        auto opened = p.take<ServiceSessionOpened>(p.service_events);
        REQUIRE(opened.size() == 1);
        CHECK(opened[0].username == "alice");
        CHECK(p.service.username() == "alice");

        MessageEntry logout;
        logout.entry_type = MessageEntryType::ClientSessionOpReq;
        logout.member_name = "LogoutUser";
        logout.elements.push_back(make_string_element("username", "alice"));
        REQUIRE(p.client.request(std::move(logout), p.now));
        p.pump();
        auto users = p.take<ServiceSessionUser>(p.service_events);
        REQUIRE(users.size() == 1);
        CHECK(users[0].username.empty());

        auto id = p.client.request(member_request("a"), p.now);
        REQUIRE(id);
        p.pump();
        CHECK(p.take<ServiceRequest>(p.service_events).empty());  // never reaches the service
        auto responses = p.take_client<ClientResponse>();
        REQUIRE(responses.size() == 2);  // logout OK, then the refused request
        REQUIRE(responses[1].entry);
        CHECK(responses[1].entry->error == MessageErrorType::PermissionDenied);
    }
}

TEST_CASE("service session: lock operations reach a service that handles locks, others answer as before") {
    auto op = [](const char* name) {
        MessageEntry e;
        e.entry_type = MessageEntryType::ClientSessionOpReq;
        e.service_path = "svc";
        e.member_name = name;
        return e;
    };
    const char* ops[] = {"RequestObjectLock", "RequestClientObjectLock", "ReleaseObjectLock", "ReleaseClientObjectLock",
                         "MonitorEnter",      "MonitorContinueEnter",    "MonitorExit"};
    SECTION("handles_locks: every lock operation is a ServiceRequest") {
        Pair p;
        p.host.service->locks = true;
        p.connect();
        for (const char* name : ops) REQUIRE(p.client.request(op(name), p.now));
        p.pump();
        auto requests = p.take<ServiceRequest>(p.service_events);
        REQUIRE(requests.size() == std::size(ops));
        for (std::size_t i = 0; i < std::size(ops); ++i) {
            CHECK(requests[i].entry().member_name == ops[i]);
            CHECK(requests[i].needs_reply);
        }
        CHECK(p.take_client<ClientResponse>().empty());  // the service answers
    }
    SECTION("without: object locks InvalidOperation, monitor operations OK") {
        Pair p;
        p.connect();
        for (const char* name : ops) REQUIRE(p.client.request(op(name), p.now));
        p.pump();
        CHECK(p.take<ServiceRequest>(p.service_events).empty());
        auto responses = p.take_client<ClientResponse>();
        REQUIRE(responses.size() == std::size(ops));
        for (std::size_t i = 0; i < 4; ++i) CHECK(responses[i].entry->error == MessageErrorType::InvalidOperation);
        for (std::size_t i = 4; i < 7; ++i) CHECK(responses[i].entry->error == MessageErrorType::None);
    }
}

TEST_CASE("service session: connect-time login errors are CORE's") {
    SECTION("no username for a service that requires a login") {
        Pair p("svc", true);
        p.pump();
        auto closed = p.take_client<ClientSessionClosed>();
        REQUIRE(closed.size() == 1);
        CHECK(closed[0].error.type == MessageErrorType::AuthenticationError);
        CHECK(closed[0].error.message == "Username not provided");
    }
    SECTION("credentials for a service without logins") {
        Pair p("svc", false, "alice", "secret");
        p.pump();
        auto closed = p.take_client<ClientSessionClosed>();
        REQUIRE(closed.size() == 1);
        CHECK(closed[0].error.message == "Authentication not enabled for service");
    }
}

TEST_CASE("service session: a service that admits sessions itself answers the connect later") {
    SECTION("admitted: the connect waits, then opens with the reserved endpoint; logins go to the service") {
        Pair p("svc", false, "alice", "pw");
        p.host.service->admits = true;
        p.host.service->auth = true;  // not asked: the service decides
        p.pump();
        auto asks = p.take<ServiceAdmission>(p.service_events);
        REQUIRE(asks.size() == 1);
        CHECK(asks[0].username == "alice");
        REQUIRE(asks[0].credentials);
        const MessageElement* pw = asks[0].credentials->find("password");
        REQUIRE(pw);
        CHECK(read_string(*pw) == "pw");
        CHECK(p.host.live.count(asks[0].endpoint) == 1);
        CHECK(p.take_client<ClientSessionConnected>().empty());  // still waiting
        CHECK(p.take<ServiceSessionOpened>(p.service_events).empty());
        CHECK(!p.service.answer_admission(asks[0].token + 1, {}, p.now));  // unknown token
        REQUIRE(p.service.answer_admission(asks[0].token, {}, p.now));
        p.pump();
        REQUIRE(p.take_client<ClientSessionConnected>().size() == 1);
        auto opened = p.take<ServiceSessionOpened>(p.service_events);
        REQUIRE(opened.size() == 1);
        CHECK(opened[0].endpoint == asks[0].endpoint);
        CHECK(opened[0].username == "alice");

        MessageEntry auth;
        auth.entry_type = MessageEntryType::ClientSessionOpReq;
        auth.service_path = "svc";
        auth.member_name = "AuthenticateUser";
        auth.elements.push_back(make_string_element("username", "bob"));
        REQUIRE(p.client.request(std::move(auth), p.now));
        REQUIRE(p.client.request(member_request("a"), p.now));  // no PermissionDenied: the service decides
        p.pump();
        auto requests = p.take<ServiceRequest>(p.service_events);
        REQUIRE(requests.size() == 2);
        CHECK(requests[0].entry().member_name == "AuthenticateUser");
        CHECK(requests[1].entry().member_name == "a");
    }
    SECTION("refused: the client gets the service's error, the endpoint is freed") {
        Pair p("svc", false, "alice", "wrong");
        p.host.service->admits = true;
        p.pump();
        auto asks = p.take<ServiceAdmission>(p.service_events);
        REQUIRE(asks.size() == 1);
        REQUIRE(p.service.answer_admission(asks[0].token,
                                           fail(MessageErrorType::AuthenticationError, "Invalid username or password"), p.now));
        p.pump();
        auto closed = p.take_client<ClientSessionClosed>();
        REQUIRE(closed.size() == 1);
        CHECK(closed[0].error.type == MessageErrorType::AuthenticationError);
        CHECK(closed[0].error.message == "Invalid username or password");
        CHECK(p.host.live.empty());
        CHECK(p.take<ServiceSessionOpened>(p.service_events).empty());
    }
    SECTION("no login: username empty, no credentials; the connection closes before the answer") {
        Pair p("svc");
        p.host.service->admits = true;
        p.pump();
        auto asks = p.take<ServiceAdmission>(p.service_events);
        REQUIRE(asks.size() == 1);
        CHECK(asks[0].username.empty());
        CHECK(!asks[0].credentials);
        p.service.on_transport_closed(make_error(MessageErrorType::ConnectionError, "gone"));
        CHECK(p.host.live.empty());
        CHECK(!p.service.answer_admission(asks[0].token, {}, p.now));  // the host then abandons it
    }
}

TEST_CASE("service session: a service that admits sessions ends them itself: DisconnectClientRet waits for it") {
    Pair p;
    p.host.service->admits = true;
    p.pump();
    auto asks = p.take<ServiceAdmission>(p.service_events);
    REQUIRE(asks.size() == 1);
    REQUIRE(p.service.answer_admission(asks[0].token, {}, p.now));
    p.pump();
    REQUIRE(p.take_client<ClientSessionConnected>().size() == 1);
    REQUIRE(p.take<ServiceSessionOpened>(p.service_events).size() == 1);

    p.client.disconnect(p.now);
    p.pump();
    auto closed = p.take<ServiceSessionClosed>(p.service_events);
    REQUIRE(closed.size() == 1);
    CHECK(closed[0].endpoint == asks[0].endpoint);
    REQUIRE(closed[0].disconnect_token != 0);
    CHECK_FALSE(p.service.has_session());
    CHECK(p.host.live.empty());
    CHECK(p.service.pending_output_size() == 0);  // no DisconnectClientRet yet
    CHECK(p.take_client<ClientSessionClosed>().empty());  // the client still waits for it

    CHECK_FALSE(p.service.answer_disconnect(closed[0].disconnect_token + 1, p.now));  // unknown token
    REQUIRE(p.service.answer_disconnect(closed[0].disconnect_token, p.now));
    CHECK_FALSE(p.service.answer_disconnect(closed[0].disconnect_token, p.now));  // answered once
    p.pump();
    CHECK(p.take_client<ClientSessionClosed>().size() == 1);  // the reply closed it, not the 500 ms wait

    {  // the connection closes before the service has ended its side: nothing to answer
        Pair q;
        q.host.service->admits = true;
        q.pump();
        auto a = q.take<ServiceAdmission>(q.service_events);
        REQUIRE(a.size() == 1);
        REQUIRE(q.service.answer_admission(a[0].token, {}, q.now));
        q.pump();
        q.client.disconnect(q.now);
        q.pump();
        auto c = q.take<ServiceSessionClosed>(q.service_events);
        REQUIRE(c.size() == 1);
        q.service.on_transport_closed(make_error(MessageErrorType::ConnectionError, "gone"));
        CHECK_FALSE(q.service.answer_disconnect(c[0].disconnect_token, q.now));
    }
}

TEST_CASE("service session: ObjectTypeName is asked of the host and answered later") {
    Pair p;
    p.connect();
    MessageEntry q;
    q.entry_type = MessageEntryType::ObjectTypeName;
    q.service_path = "svc.child";
    auto id = p.client.request(std::move(q), p.now);
    REQUIRE(id);
    p.pump();
    auto queries = p.take<ServiceObjectTypeQuery>(p.service_events);
    REQUIRE(queries.size() == 1);
    CHECK(queries[0].path == "svc.child");
    CHECK(p.take_client<ClientResponse>().empty());
    p.service.answer_object_type(queries[0].token, ObjectTypeInfo{"example.svc.Child", {}}, p.now);
    p.service.answer_object_type(queries[0].token, ObjectTypeInfo{"twice", {}}, p.now);  // ignored
    p.pump();
    auto responses = p.take_client<ClientResponse>();
    REQUIRE(responses.size() == 1);
    REQUIRE(responses[0].entry);
    REQUIRE(responses[0].entry->find("objecttype"));
    CHECK(read_string(*responses[0].entry->find("objecttype")) == "example.svc.Child");
}

TEST_CASE("service session: callbacks to the client are answered, time out, or fail on disconnect") {
    Pair p;
    p.connect();
    MessageEntry cb = member_request("cb", MessageEntryType::CallbackCallReq);
    auto id = p.service.request(cb, p.now);
    REQUIRE(id);
    p.pump();
    auto incoming = p.take_client<ClientIncoming>();
    REQUIRE(incoming.size() == 1);
    CHECK(incoming[0].entry.entry_type == MessageEntryType::CallbackCallReq);
    MessageEntry answer = reply_to(incoming[0].entry);
    answer.elements.push_back(make_scalar_element<double>("return", 2.5));
    REQUIRE(p.client.reply(std::move(answer), p.now));
    p.pump();
    auto responses = p.take<ServiceCallbackResponse>(p.service_events);
    REQUIRE(responses.size() == 1);
    CHECK(responses[0].request_id == *id);
    REQUIRE(responses[0].entry);

    // Unanswered: RequestTimeout once the deadline passes.
    auto id2 = p.service.request(cb, p.now);
    REQUIRE(id2);
    p.pump();
    REQUIRE(p.service.next_deadline());
    p.now += 3s;
    p.service.on_timer(p.now);
    while (auto e = p.service.poll_event()) p.service_events.push_back(std::move(*e));
    responses = p.take<ServiceCallbackResponse>(p.service_events);
    REQUIRE(responses.size() == 1);
    CHECK(responses[0].request_id == *id2);
    REQUIRE_FALSE(responses[0].entry);
    CHECK(responses[0].entry.error().type == MessageErrorType::RequestTimeout);

    // Pending when the transport goes: ConnectionError, then the session and the connection close.
    auto id3 = p.service.request(cb, p.now);
    REQUIRE(id3);
    p.service.on_transport_closed(make_error(MessageErrorType::ConnectionError, "gone"));
    while (auto e = p.service.poll_event()) p.service_events.push_back(std::move(*e));
    responses = p.take<ServiceCallbackResponse>(p.service_events);
    REQUIRE(responses.size() == 1);
    CHECK(responses[0].entry.error().type == MessageErrorType::ConnectionError);
    CHECK(p.take<ServiceSessionClosed>(p.service_events).size() == 1);
    CHECK(p.take<ServiceConnectionClosed>(p.service_events).size() == 1);
    CHECK(p.host.live.empty());
    CHECK(p.service.is_closed());
}

namespace {

// (member, int32 "value") of every incoming entry after the first, sorted.
template <class Incoming>
std::vector<std::pair<std::string, std::int32_t>> wire_values(const std::vector<Incoming>& incoming) {
    std::vector<std::pair<std::string, std::int32_t>> wires;
    for (std::size_t i = 1; i < incoming.size(); ++i) {
        std::int32_t v = 0;
        const MessageElement* e = incoming[i].entry.find("value");
        if (e && read_scalar(*e, v)) wires.emplace_back(incoming[i].entry.member_name, v);
    }
    std::sort(wires.begin(), wires.end());
    return wires;
}

}  // namespace

TEST_CASE("service session: wire packets wait while output is backed up, only the newest per member") {
    Pair p;
    p.connect();
    // Back the output up past wire_hold_bytes (1024) without handing it to the transport.
    MessageEntry ev = member_request("ev", MessageEntryType::EventReq);
    std::vector<std::uint8_t> payload(4096);
    ev.elements.push_back(make_array_element<std::uint8_t>("p", payload));
    REQUIRE(p.service.send(ev, p.now));
    for (int i = 1; i <= 3; ++i) {
        MessageEntry w = member_request("w", MessageEntryType::WirePacket);
        w.elements.push_back(make_scalar_element<std::int32_t>("value", i));
        p.service.send_wire_packet(std::move(w), p.now);
    }
    MessageEntry other = member_request("w2", MessageEntryType::WirePacket);
    other.elements.push_back(make_scalar_element<std::int32_t>("value", 9));
    p.service.send_wire_packet(std::move(other), p.now);
    p.pump();
    auto incoming = p.take_client<ClientIncoming>();
    REQUIRE(incoming.size() == 3);  // the event, then the newest value of each wire
    CHECK(incoming[0].entry.entry_type == MessageEntryType::EventReq);
    CHECK(wire_values(incoming) == std::vector<std::pair<std::string, std::int32_t>>{{"w", 3}, {"w2", 9}});
}

TEST_CASE("service session: an entry shared by many sessions (EncodedEntry) arrives as one of its own") {
    Pair p;
    p.connect();
    MessageEntry ev = member_request("ev", MessageEntryType::EventReq);
    ev.elements.push_back(make_array_element<double>("a", std::vector<double>{1.5, 2.5}));
    const auto shared_event = std::make_shared<const EncodedEntry>(ev);
    REQUIRE(p.service.send(*shared_event, p.now));
    MessageEntry w = member_request("w", MessageEntryType::WirePacket);
    w.elements.push_back(make_scalar_element<std::int32_t>("value", 5));
    p.service.send_wire_packet(std::make_shared<const EncodedEntry>(w), p.now);
    p.pump();
    auto incoming = p.take_client<ClientIncoming>();
    REQUIRE(incoming.size() == 2);
    CHECK(incoming[0].entry == ev);
    CHECK(incoming[1].entry == w);

    SECTION("held while output is backed up: the newest value, shared or not, wins") {
        MessageEntry big = member_request("ev", MessageEntryType::EventReq);
        big.elements.push_back(make_array_element<std::uint8_t>("p", std::vector<std::uint8_t>(4096)));
        REQUIRE(p.service.send(big, p.now));
        for (int i = 1; i <= 3; ++i) {
            MessageEntry v = member_request("w", MessageEntryType::WirePacket);
            v.elements.push_back(make_scalar_element<std::int32_t>("value", 10 + i));
            if (i % 2)
                p.service.send_wire_packet(std::make_shared<const EncodedEntry>(std::move(v)), p.now);
            else
                p.service.send_wire_packet(std::move(v), p.now);
        }
        MessageEntry v2 = member_request("w2", MessageEntryType::WirePacket);
        v2.elements.push_back(make_scalar_element<std::int32_t>("value", 7));
        p.service.send_wire_packet(std::move(v2), p.now);
        p.pump();
        incoming = p.take_client<ClientIncoming>();
        REQUIRE(incoming.size() == 3);  // the event, then the newest value of each wire
        CHECK(wire_values(incoming) == std::vector<std::pair<std::string, std::int32_t>>{{"w", 13}, {"w2", 7}});
    }
    SECTION("an entry that cannot be encoded is an error, and the session goes on") {
        MessageEntry bad = member_request("ev", MessageEntryType::EventReq);
        MessageElement e;
        e.name = "odd";
        e.type = DataTypes::double_t;
        e.data = SharedBytes::copy_of("abc", 3);  // not a multiple of 8 bytes
        bad.elements.push_back(std::move(e));
        auto r = p.service.send(EncodedEntry(std::move(bad)), p.now);
        REQUIRE_FALSE(r);
        CHECK(r.error().type == MessageErrorType::InvalidArgument);
        REQUIRE(p.service.send(*shared_event, p.now));
        p.pump();
        incoming = p.take_client<ClientIncoming>();
        REQUIRE(incoming.size() == 1);
        CHECK(incoming[0].entry == ev);
    }
}

TEST_CASE("service session: DisconnectClient ends the session and frees its endpoint, sends then fail") {
    Pair p;
    p.connect();
    const auto endpoint = p.service.endpoint();
    p.client.disconnect(p.now);
    p.pump();
    auto closed = p.take<ServiceSessionClosed>(p.service_events);
    REQUIRE(closed.size() == 1);
    CHECK(closed[0].endpoint == endpoint);
    CHECK(closed[0].disconnect_token == 0);  // answered at once
    CHECK(p.take_client<ClientSessionClosed>().size() == 1);
    CHECK(p.host.live.empty());
    CHECK_FALSE(p.service.has_session());
    auto r = p.service.send(member_request("ev", MessageEntryType::EventReq), p.now);
    REQUIRE_FALSE(r);
    CHECK(r.error().type == MessageErrorType::InvalidState);
}

TEST_CASE("service session: requests for another endpoint or before a session get InvalidEndpoint") {
    Pair p;
    p.pump();  // stream + session up
    REQUIRE(p.take_client<ClientSessionConnected>().size() == 1);
    // A hand-made message to a wrong endpoint, straight into the service side.
    StreamConnection raw(StreamRole::client, [] {
        StreamConfig c;
        c.local_node_id = kClientId;
        return c;
    }(), p.now);
    ServiceSession fresh(p.host, Pair::service_config(), p.now);
    std::vector<std::byte> buf;
    raw.take_output(buf);
    fresh.feed(buf, p.now);
    fresh.take_output(buf);
    REQUIRE(raw.feed(buf, p.now));
    Message m;
    m.header.sender_node_id = kClientId;
    m.header.receiver_node_id = kServiceNodeId;
    m.header.sender_endpoint = 5;
    m.header.receiver_endpoint = 12345;
    MessageEntry e = member_request("a");
    e.request_id = 1;
    m.entries.push_back(e);
    REQUIRE(raw.send(m, p.now));
    raw.take_output(buf);
    fresh.feed(buf, p.now);
    CHECK_FALSE(fresh.poll_event());  // nothing for the host
    fresh.take_output(buf);
    REQUIRE(raw.feed(buf, p.now));
    bool got = false;
    while (auto ev = raw.poll_event()) {
        if (auto* sm = std::get_if<StreamMessage>(&*ev)) {
            REQUIRE(sm->message.entries.size() == 1);
            CHECK(sm->message.entries[0].error == MessageErrorType::InvalidEndpoint);
            got = true;
        }
    }
    CHECK(got);
}

TEST_CASE("service session: ObjectTypeName queries a client may have waiting are bounded") {
    Pair p;
    p.connect();
    for (int i = 0; i < 300; ++i) {
        MessageEntry q;
        q.entry_type = MessageEntryType::ObjectTypeName;
        q.service_path = "svc.o" + std::to_string(i);
        REQUIRE(p.client.request(std::move(q), p.now));
    }
    p.pump();
    auto queries = p.take<ServiceObjectTypeQuery>(p.service_events);
    CHECK(queries.size() == 256);
    auto responses = p.take_client<ClientResponse>();
    REQUIRE(responses.size() == 44);
    for (const auto& r : responses) {
        REQUIRE(r.entry);
        CHECK(r.entry->error == MessageErrorType::BufferLimitViolation);
    }
}
