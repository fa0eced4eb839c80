// ClientContext against a scripted entry-level service: a server StreamConnection plus hand-written
// answers. No sockets, no sleeps: time is moved by hand.
#include <catch2/catch.hpp>

#include <deque>
#include <functional>

#include "base/message/error_entry.hpp"
#include "core/session/client_context.hpp"
#include "core/session/elements.hpp"
#include "core/value/pack_value.hpp"

using namespace rr;
using namespace std::chrono_literals;

namespace {

const NodeID kClientId = *NodeID::parse("11111111-2222-3333-4444-555555555555");
const NodeID kServerId = *NodeID::parse("aaaaaaaa-bbbb-cccc-dddd-eeeeeeeeeeee");
constexpr std::uint32_t kServiceEndpoint = 777;

constexpr std::string_view kRobdef = R"(service example.ctx
stdver 0.10
import example.other

exception Fault

struct Point
    field double x
    field double y
end

object Root
    property double speed
    property int32 ro [readonly]
    property int32 wo [writeonly]
    property Point where
    function int32 add(int32 a, int32 b)
    function void fault()
    function void slow()
    function int32{generator} count(int32 n)
    function double{generator} sum(double{generator} x)
    event moved(int32 seq, Point p)
    objref Child child
    objref Child{int32} kids
    objref varobject anything
    pipe double[] samples
    pipe string chat [unreliable]
    pipe int32 ro_pipe [readonly]
    callback double scale(double x)
    callback void ping()
    wire Point pose
    wire int32 ro_wire [readonly]
    wire int32 wo_wire [writeonly]
    memory double[] buf
    memory int32[*] grid
end

object Child
    property string name
    pipe double[] data
end
)";

constexpr std::string_view kOtherRobdef = R"(service example.other
stdver 0.10
struct Unused
    field int32 k
end
)";

constexpr std::string_view kPulledRobdef = R"(service example.far
stdver 0.10
object Thing
    property int32 level
end
)";

MessageElement string_list(std::string name, std::vector<std::string_view> items) {
    MessageElement e;
    e.name = std::move(name);
    e.type = DataTypes::list_t;
    std::int32_t n = 0;
    for (auto s : items) {
        auto c = make_string_element("", s);
        c.number = n++;
        e.elements.push_back(std::move(c));
    }
    return e;
}

MessageEntry error_reply(const MessageEntry& req, RRError err) {
    auto r = reply_to(req);
    set_entry_error(r, err);
    return r;
}

MessageElement point_element(std::string name, double x, double y) {
    MessageElement e;
    e.name = std::move(name);
    e.type = DataTypes::structure_t;
    e.type_name = "example.ctx.Point";
    e.elements.push_back(make_scalar_element("x", x));
    e.elements.push_back(make_scalar_element("y", y));
    return e;
}

Value point(double x, double y) {
    return Value(Structure{"example.ctx.Point", {{"x", Value::scalar(x)}, {"y", Value::scalar(y)}}});
}

/// What the scripted service answers: an entry (reply), or nothing (no answer).
using Script = std::function<std::optional<MessageEntry>(const MessageEntry& request)>;

struct ScriptedService {
    StreamConnection stream;
    std::vector<MessageEntry> received;
    Script script;
    std::uint32_t client_endpoint = 0;
    std::string root_type = "example.ctx.Root";

    explicit ScriptedService(MonoTime t0)
        : stream(StreamRole::server, [] {
              StreamConfig c;
              c.local_node_id = kServerId;
              c.local_node_name = "scripted";
              return c;
          }(), t0) {}

    void send(MessageEntry e, MonoTime now) {
        Message m;
        m.header.sender_node_id = kServerId;
        m.header.receiver_node_id = kClientId;
        m.header.sender_endpoint = kServiceEndpoint;
        m.header.receiver_endpoint = client_endpoint;
        m.entries.push_back(std::move(e));
        REQUIRE(stream.send(m, now));
    }

    void handle(MonoTime now) {
        while (auto ev = stream.poll_event()) {
            auto* sm = std::get_if<StreamMessage>(&*ev);
            if (!sm) continue;
            for (auto& e : sm->message.entries) {
                received.push_back(e);
                if (e.entry_type == MessageEntryType::ConnectClientCombined) {
                    client_endpoint = sm->message.header.sender_endpoint;
                    auto r = reply_to(e);
                    r.elements.push_back(make_string_element("objecttype", root_type));
                    r.elements.push_back(string_list("servicedefs", {kRobdef, kOtherRobdef}));
                    send(std::move(r), now);
                    stream.set_session_established(kServiceEndpoint, client_endpoint);
                    continue;
                }
                if (e.entry_type == MessageEntryType::DisconnectClient) {
                    send(reply_to(e), now);
                    continue;
                }
                if (script) {
                    if (auto r = script(e)) send(std::move(*r), now);
                }
            }
        }
    }

    std::vector<MessageEntry> of_type(MessageEntryType t) const {
        std::vector<MessageEntry> out;
        for (const auto& e : received)
            if (e.entry_type == t) out.push_back(e);
        return out;
    }
};

void pump(ClientContext& c, ScriptedService& s, MonoTime now) {
    for (int i = 0; i < 50; ++i) {
        std::vector<std::byte> x;
        c.take_output(x);
        if (!x.empty()) (void)s.stream.feed(x, now);
        s.handle(now);
        std::vector<std::byte> y;
        s.stream.take_output(y);
        if (!y.empty()) (void)c.feed(y, now);
        if (x.empty() && y.empty()) return;
    }
}

ClientContextConfig config() {
    ClientContextConfig c;
    c.session.stream.local_node_id = kClientId;
    c.session.service_name = "svc";
    c.session.local_endpoint = 4242;
    return c;
}

/// Captures a completion's result.
template <class T>
struct Got {
    std::optional<Result<T>> r;
    Completion<T> cb() {
        return [this](Result<T> x) { r.emplace(std::move(x)); };
    }
    bool ready() const { return r.has_value(); }
    const T& value() const {
        REQUIRE(r);
        INFO((r->ok() ? std::string() : r->error().message));
        REQUIRE(r->ok());
        return r->value();
    }
    const RRError& error() const {
        REQUIRE(r);
        REQUIRE_FALSE(r->ok());
        return r->error();
    }
};
template <>
struct Got<void> {
    std::optional<Result<void>> r;
    Completion<void> cb() {
        return [this](Result<void> x) { r.emplace(std::move(x)); };
    }
    bool ready() const { return r.has_value(); }
    void ok() const {
        REQUIRE(r);
        INFO((r->ok() ? std::string() : r->error().message));
        REQUIRE(r->ok());
    }
    const RRError& error() const {
        REQUIRE(r);
        REQUIRE_FALSE(r->ok());
        return r->error();
    }
};

struct Fixture {
    MonoTime t0{};
    ClientContext c{config(), t0};
    ScriptedService s{t0};
    ObjectRef root;

    Fixture() {
        Got<ObjectRef> connected;
        c.set_connect_handler(connected.cb());
        pump(c, s, t0);
        root = connected.value();
    }
    void run() { pump(c, s, t0); }
};

}  // namespace

TEST_CASE("client context connects and knows the root object and its definitions") {
    Fixture f;
    CHECK(f.root.path == "svc");
    CHECK(f.root.type == "example.ctx.Root");
    CHECK(f.c.is_connected());
    CHECK(f.c.definitions().find_service("example.ctx") != nullptr);
    CHECK(f.c.definitions().find_service("example.other") != nullptr);
    CHECK(f.c.implements("svc", "example.ctx.Root"));
    CHECK_FALSE(f.c.implements("svc", "example.ctx.Child"));
    auto m = f.c.member_definition("svc", "speed");
    REQUIRE(m);
    CHECK((*m)->kind == robdef::MemberKind::property);
    CHECK(f.c.member_definition("svc", "nope").error().type == MessageErrorType::MemberNotFound);
}

TEST_CASE("client context fails the connect when the root type is not defined") {
    MonoTime t0{};
    ClientContext c(config(), t0);
    ScriptedService s(t0);
    s.root_type = "example.ctx.Missing";
    Got<ObjectRef> connected;
    c.set_connect_handler(connected.cb());
    pump(c, s, t0);
    CHECK(connected.error().type == MessageErrorType::ServiceDefinitionError);
    CHECK_FALSE(c.is_connected());
}

TEST_CASE("properties: get and set typed by the robdef, direction and member checks") {
    Fixture f;
    std::vector<MessageEntry> sets;
    f.s.script = [&](const MessageEntry& e) -> std::optional<MessageEntry> {
        auto r = reply_to(e);
        if (e.entry_type == MessageEntryType::PropertyGetReq && e.member_name == "speed") {
            r.elements.push_back(make_scalar_element("value", 2.5));
        } else if (e.entry_type == MessageEntryType::PropertyGetReq && e.member_name == "where") {
            r.elements.push_back(point_element("value", 1, -1));
        } else if (e.entry_type == MessageEntryType::PropertySetReq) {
            sets.push_back(e);
            if (e.member_name == "where") return error_reply(e, RRError{MessageErrorType::RemoteError, "example.ctx.Fault", "no", "", nullptr});
        } else {
            return std::nullopt;
        }
        return r;
    };
    Got<Value> speed, where;
    f.c.property_get("svc", "speed", f.t0, speed.cb());
    f.c.property_get("svc", "where", f.t0, where.cb());
    CHECK_FALSE(speed.ready());  // answered only after the bytes move
    f.run();
    CHECK(speed.value() == Value::scalar(2.5));
    CHECK(where.value() == point(1, -1));

    Got<void> set_ok;
    f.c.property_set("svc", "speed", Value::scalar(4.0), f.t0, set_ok.cb());
    f.run();
    set_ok.ok();
    REQUIRE(sets.size() == 1);
    double v = 0;
    REQUIRE(read_scalar(*sets[0].find("value"), v));
    CHECK(v == 4.0);

    SECTION("a user error from the service keeps its name") {
        Got<void> bad;
        f.c.property_set("svc", "where", point(0, 0), f.t0, bad.cb());
        f.run();
        CHECK(bad.error().type == MessageErrorType::RemoteError);
        CHECK(bad.error().name == "example.ctx.Fault");
        CHECK(bad.error().message == "no");
    }
    SECTION("local failures are reported at once and send nothing") {
        const auto before = f.s.received.size();
        Got<void> mismatch, ro, no_member, kind;
        Got<Value> wo;
        f.c.property_set("svc", "speed", Value("fast"), f.t0, mismatch.cb());
        f.c.property_set("svc", "ro", Value::scalar(std::int32_t{1}), f.t0, ro.cb());
        f.c.property_get("svc", "wo", f.t0, wo.cb());
        f.c.property_set("svc", "nope", Value::scalar(1.0), f.t0, no_member.cb());
        f.c.property_set("svc", "add", Value::scalar(1.0), f.t0, kind.cb());
        CHECK(mismatch.error().type == MessageErrorType::DataTypeMismatch);
        CHECK(ro.error().type == MessageErrorType::ReadOnlyMember);
        CHECK(wo.error().type == MessageErrorType::WriteOnlyMember);
        CHECK(no_member.error().type == MessageErrorType::MemberNotFound);
        CHECK(kind.error().type == MessageErrorType::InvalidOperation);
        Got<Value> unknown_path;
        f.c.property_get("svc.child", "name", f.t0, unknown_path.cb());
        CHECK(unknown_path.error().type == MessageErrorType::ObjectNotFound);
        f.run();
        CHECK(f.s.received.size() == before);
    }
}

TEST_CASE("functions: positional arguments, return, void, argument count, user errors") {
    Fixture f;
    f.s.script = [&](const MessageEntry& e) -> std::optional<MessageEntry> {
        if (e.entry_type != MessageEntryType::FunctionCallReq) return std::nullopt;
        auto r = reply_to(e);
        if (e.member_name == "add") {
            std::int32_t a = 0, b = 0;
            REQUIRE(read_scalar(*e.find("a"), a));
            REQUIRE(read_scalar(*e.find("b"), b));
            r.elements.push_back(make_scalar_element("return", a + b));
        } else if (e.member_name == "fault") {
            return error_reply(e, RRError{MessageErrorType::RemoteError, "example.ctx.Fault", "broken", "", nullptr});
        } else {
            r.elements.push_back(make_scalar_element<std::int32_t>("return", 0));
        }
        return r;
    };
    Got<Value> sum, none, fault, count;
    f.c.call("svc", "add", {Value::scalar(std::int32_t{2}), Value::scalar(std::int32_t{40})}, f.t0, sum.cb());
    f.c.call("svc", "slow", {}, f.t0, none.cb());
    f.c.call("svc", "fault", {}, f.t0, fault.cb());
    f.c.call("svc", "add", {Value::scalar(std::int32_t{2})}, f.t0, count.cb());
    CHECK(count.error().type == MessageErrorType::InvalidArgument);
    f.run();
    CHECK(sum.value() == Value::scalar(std::int32_t{42}));
    CHECK(none.value().is_null());
    CHECK(fault.error().type == MessageErrorType::RemoteError);
    CHECK(fault.error().name == "example.ctx.Fault");

    SECTION("a completion may start the next request") {
        Got<Value> second;
        f.c.call("svc", "add", {Value::scalar(std::int32_t{1}), Value::scalar(std::int32_t{1})}, f.t0,
                 [&](Result<Value> r) {
                     REQUIRE(r);
                     f.c.call("svc", "add", {*r, Value::scalar(std::int32_t{10})}, f.c.now(), second.cb());
                 });
        f.run();
        CHECK(second.value() == Value::scalar(std::int32_t{12}));
    }
}

TEST_CASE("generators: next to StopIteration, close and abort requests, parameter generators") {
    Fixture f;
    std::int32_t next_value = 0;
    f.s.script = [&](const MessageEntry& e) -> std::optional<MessageEntry> {
        auto r = reply_to(e);
        if (e.entry_type == MessageEntryType::FunctionCallReq) {
            r.elements.push_back(make_scalar_element<std::int32_t>("index", e.member_name == "count" ? 5 : 6));
            return r;
        }
        if (e.entry_type != MessageEntryType::GeneratorNextReq) return std::nullopt;
        if (e.error != MessageErrorType::None) return r;  // close / abort acknowledged
        if (e.member_name == "sum") {
            double x = 0;
            REQUIRE(read_scalar(*e.find("parameter"), x));
            r.elements.push_back(make_scalar_element("return", x * 10));
            return r;
        }
        if (next_value >= 2) return error_reply(e, make_error(MessageErrorType::StopIteration, ""));
        r.elements.push_back(make_scalar_element("return", next_value++));
        return r;
    };
    Got<GeneratorHandle> g;
    f.c.call_generator("svc", "count", {Value::scalar(std::int32_t{2})}, f.t0, g.cb());
    f.run();
    REQUIRE(g.value());
    Got<Value> a, b, end, after;
    f.c.generator_next(g.value(), std::nullopt, f.t0, a.cb());
    f.run();
    f.c.generator_next(g.value(), std::nullopt, f.t0, b.cb());
    f.run();
    f.c.generator_next(g.value(), std::nullopt, f.t0, end.cb());
    f.run();
    CHECK(a.value() == Value::scalar(std::int32_t{0}));
    CHECK(b.value() == Value::scalar(std::int32_t{1}));
    CHECK(end.error().type == MessageErrorType::StopIteration);
    f.c.generator_next(g.value(), std::nullopt, f.t0, after.cb());
    CHECK(after.error().type == MessageErrorType::InvalidOperation);  // forgotten after StopIteration
    auto nexts = f.s.of_type(MessageEntryType::GeneratorNextReq);
    REQUIRE(nexts.size() == 3);
    std::int32_t idx = 0;
    REQUIRE(read_scalar(*nexts[0].find("index"), idx));
    CHECK(idx == 5);
    CHECK(nexts[0].find("parameter") == nullptr);

    Got<void> closed, aborted;
    Got<GeneratorHandle> g2, g3;
    f.c.call_generator("svc", "sum", {}, f.t0, g2.cb());
    f.c.call_generator("svc", "count", {Value::scalar(std::int32_t{9})}, f.t0, g3.cb());
    f.run();
    Got<Value> s1, missing;
    f.c.generator_next(g2.value(), Value::scalar(1.5), f.t0, s1.cb());
    f.c.generator_next(g2.value(), std::nullopt, f.t0, missing.cb());
    CHECK(missing.error().type == MessageErrorType::InvalidArgument);
    f.run();
    CHECK(s1.value() == Value::scalar(15.0));
    f.c.generator_close(g2.value(), f.t0, closed.cb());
    f.c.generator_abort(g3.value(), f.t0, aborted.cb());
    f.run();
    closed.ok();
    aborted.ok();
    nexts = f.s.of_type(MessageEntryType::GeneratorNextReq);
    REQUIRE(nexts.size() >= 2);
    const auto& close_req = nexts[nexts.size() - 2];
    const auto& abort_req = nexts.back();
    CHECK(close_req.error == MessageErrorType::StopIteration);
    CHECK(read_string(*close_req.find("errorname")) == "RobotRaconteur.StopIteration");
    REQUIRE(read_scalar(*close_req.find("index"), idx));
    CHECK(idx == 6);
    CHECK(abort_req.error == MessageErrorType::AbortOperation);
    CHECK(read_string(*abort_req.find("errorname")) == "RobotRaconteur.AbortOperation");
    Got<void> twice;
    f.c.generator_close(g2.value(), f.t0, twice.cb());
    CHECK(twice.error().type == MessageErrorType::InvalidOperation);
}

TEST_CASE("objrefs: encoded service paths, typed objects, cache, pulled definitions, release") {
    Fixture f;
    int typename_requests = 0;
    f.s.script = [&](const MessageEntry& e) -> std::optional<MessageEntry> {
        auto r = reply_to(e);
        if (e.entry_type == MessageEntryType::ObjectTypeName) {
            ++typename_requests;
            CHECK(e.find("clientversion"));
            if (e.service_path == "svc.kids[99]") return error_reply(e, make_error(MessageErrorType::ObjectNotFound, "no kid"));
            r.elements.push_back(make_string_element("objecttype", e.service_path == "svc.anything" ? "example.far.Thing" : "example.ctx.Child"));
            return r;
        }
        if (e.entry_type == MessageEntryType::GetServiceDesc) {
            CHECK(read_string(*e.find("ServiceType")) == "example.far");
            r.elements.push_back(make_string_element("servicedef", kPulledRobdef));
            return r;
        }
        if (e.entry_type == MessageEntryType::PropertyGetReq) {
            if (e.member_name == "name") r.elements.push_back(make_string_element("value", e.service_path));
            else r.elements.push_back(make_scalar_element<std::int32_t>("value", 3));
            return r;
        }
        if (e.entry_type == MessageEntryType::PipeConnectReq) {
            r.elements.push_back(make_scalar_element<std::int32_t>("index", 1));
            return r;
        }
        return std::nullopt;
    };
    Got<ObjectRef> child, kid, far, missing, cached;
    f.c.objref("svc", "child", {}, f.t0, child.cb());
    f.c.objref("svc", "kids", std::int32_t{-1}, f.t0, kid.cb());
    f.c.objref("svc", "anything", {}, f.t0, far.cb());
    f.c.objref("svc", "kids", std::int32_t{99}, f.t0, missing.cb());
    f.run();
    CHECK(child.value().path == "svc.child");
    CHECK(child.value().type == "example.ctx.Child");
    CHECK(kid.value().path == "svc.kids[%2d1]");
    CHECK(far.value().type == "example.far.Thing");
    CHECK(f.c.definitions().find_service("example.far") != nullptr);
    CHECK(missing.error().type == MessageErrorType::ObjectNotFound);
    CHECK(typename_requests == 4);
    f.c.objref("svc", "child", {}, f.t0, cached.cb());
    CHECK(cached.value().path == "svc.child");  // from the cache, no request
    CHECK(typename_requests == 4);

    Got<ObjectRef> bad_index;
    f.c.objref("svc", "kids", std::string("x"), f.t0, bad_index.cb());
    CHECK(bad_index.error().type == MessageErrorType::InvalidArgument);

    Got<Value> name, level;
    f.c.property_get("svc.kids[%2d1]", "name", f.t0, name.cb());
    f.c.property_get("svc.anything", "level", f.t0, level.cb());
    f.run();
    CHECK(name.value() == Value("svc.kids[%2d1]"));
    CHECK(level.value() == Value::scalar(std::int32_t{3}));

    // Released by the service: the object, its children and its pipe endpoints go.
    Got<PipeEndpointHandle> ep;
    f.c.pipe_connect("svc.child", "data", -1, f.t0, ep.cb());
    f.run();
    std::optional<RRError> pipe_closed;
    REQUIRE(f.c.set_pipe_handlers(ep.value(), {nullptr, nullptr, [&](PipeEndpointHandle, const RRError& e) { pipe_closed = e; }}));
    std::vector<std::string> released;
    f.c.set_path_released_handler([&](const std::string& p) { released.push_back(p); });
    MessageEntry rel;
    rel.entry_type = MessageEntryType::ServicePathReleasedReq;
    rel.service_path = "svc.child";
    f.s.send(rel, f.t0);
    f.run();
    CHECK(released == std::vector<std::string>{"svc.child"});
    CHECK_FALSE(f.c.object("svc.child"));
    CHECK(f.c.object("svc.kids[%2d1]"));
    REQUIRE(pipe_closed);
    CHECK(pipe_closed->type == MessageErrorType::ObjectNotFound);
    Got<Value> gone;
    f.c.property_get("svc.child", "name", f.t0, gone.cb());
    CHECK(gone.error().type == MessageErrorType::ObjectNotFound);
}

TEST_CASE("events are unpacked by the robdef and delivered to subscribers of that path and member") {
    Fixture f;
    std::vector<std::vector<Value>> got;
    auto sub = f.c.subscribe_event("svc", "moved", [&](const std::string& path, std::vector<Value>& args) {
        CHECK(path == "svc");
        got.push_back(args);
    });
    REQUIRE(sub);
    CHECK(f.c.subscribe_event("svc", "speed", [](const std::string&, std::vector<Value>&) {}).error().type ==
          MessageErrorType::InvalidOperation);
    MessageEntry ev;
    ev.entry_type = MessageEntryType::EventReq;
    ev.service_path = "svc";
    ev.member_name = "moved";
    ev.elements.push_back(make_scalar_element<std::int32_t>("seq", 7));
    ev.elements.push_back(point_element("p", 3, 4));
    f.s.send(ev, f.t0);
    f.run();
    REQUIRE(got.size() == 1);
    CHECK(got[0][0] == Value::scalar(std::int32_t{7}));
    CHECK(got[0][1] == point(3, 4));
    // A malformed event (missing parameter) is dropped.
    auto bad = ev;
    bad.elements.pop_back();
    f.s.send(bad, f.t0);
    f.run();
    CHECK(got.size() == 1);
    f.c.unsubscribe_event(*sub);
    f.s.send(ev, f.t0);
    f.run();
    CHECK(got.size() == 1);
}

TEST_CASE("callbacks: the handler's result or error becomes the CallbackCallRet") {
    Fixture f;
    std::vector<MessageEntry> rets;
    f.s.script = [&](const MessageEntry& e) -> std::optional<MessageEntry> {
        if (e.entry_type == MessageEntryType::CallbackCallRet) rets.push_back(e);
        return std::nullopt;
    };
    MessageEntry call;
    call.entry_type = MessageEntryType::CallbackCallReq;
    call.service_path = "svc";
    call.member_name = "scale";
    call.request_id = 31;
    call.elements.push_back(make_scalar_element("x", 1.5));

    // Not set: an error answer.
    f.s.send(call, f.t0);
    f.run();
    REQUIRE(rets.size() == 1);
    CHECK(rets[0].request_id == 31);
    CHECK(rets[0].error == MessageErrorType::InvalidOperation);

    REQUIRE(f.c.set_callback("svc", "scale", [](std::vector<Value>& args) -> Result<Value> {
        return Value::scalar(args[0].as<double>().value() * 2);
    }));
    f.s.send(call, f.t0);
    f.run();
    REQUIRE(rets.size() == 2);
    CHECK(rets[1].error == MessageErrorType::None);
    double v = 0;
    REQUIRE(read_scalar(*rets[1].find("return"), v));
    CHECK(v == 3.0);

    REQUIRE(f.c.set_callback("svc", "scale", [](std::vector<Value>&) -> Result<Value> {
        return fail(RRError{MessageErrorType::RemoteError, "example.ctx.Fault", "client says no", "", nullptr});
    }));
    f.s.send(call, f.t0);
    f.run();
    REQUIRE(rets.size() == 3);
    CHECK(rets[2].error == MessageErrorType::RemoteError);
    CHECK(read_string(*rets[2].find("errorname")) == "example.ctx.Fault");

    // A result that does not match the robdef becomes an error answer, too.
    REQUIRE(f.c.set_callback("svc", "scale", [](std::vector<Value>&) -> Result<Value> { return Value("text"); }));
    f.s.send(call, f.t0);
    f.run();
    REQUIRE(rets.size() == 4);
    CHECK(rets[3].error == MessageErrorType::DataTypeMismatch);

    // A void callback answers int32 0.
    int pings = 0;
    REQUIRE(f.c.set_callback("svc", "ping", [&](std::vector<Value>&) -> Result<Value> {
        ++pings;
        return Value();
    }));
    auto ping = call;
    ping.member_name = "ping";
    ping.elements.clear();
    f.s.send(ping, f.t0);
    f.run();
    REQUIRE(rets.size() == 5);
    CHECK(pings == 1);
    std::int32_t zero = 1;
    REQUIRE(read_scalar(*rets[4].find("return"), zero));
    CHECK(zero == 0);
}

TEST_CASE("callbacks: a deferred handler answers when it calls reply, once") {
    Fixture f;
    std::vector<MessageEntry> rets;
    f.s.script = [&](const MessageEntry& e) -> std::optional<MessageEntry> {
        if (e.entry_type == MessageEntryType::CallbackCallRet) rets.push_back(e);
        return std::nullopt;
    };
    Completion<Value> later;
    double seen = 0;
    REQUIRE(f.c.set_deferred_callback("svc", "scale", [&](std::vector<Value>& args, Completion<Value> reply) {
        seen = args[0].as<double>().value();
        later = std::move(reply);
    }));
    MessageEntry call;
    call.entry_type = MessageEntryType::CallbackCallReq;
    call.service_path = "svc";
    call.member_name = "scale";
    call.request_id = 44;
    call.elements.push_back(make_scalar_element("x", 2.5));
    f.s.send(call, f.t0);
    f.run();
    CHECK(seen == 2.5);
    CHECK(rets.empty());  // nothing is sent before the handler replies
    REQUIRE(later);
    later(Value::scalar(7.0));
    later(Value::scalar(8.0));  // a second reply is ignored
    f.run();
    REQUIRE(rets.size() == 1);
    CHECK(rets[0].request_id == 44);
    double v = 0;
    REQUIRE(read_scalar(*rets[0].find("return"), v));
    CHECK(v == 7.0);
}

TEST_CASE("pipes: connect, numbered packets, acks both ways, order, early packets, closed by the service") {
    Fixture f;
    std::vector<MessageEntry> packets;
    f.s.script = [&](const MessageEntry& e) -> std::optional<MessageEntry> {
        auto r = reply_to(e);
        switch (e.entry_type) {
            case MessageEntryType::PipeConnectReq: {
                std::int32_t idx = 0;
                REQUIRE(read_scalar(*e.find("index"), idx));
                r.elements.push_back(make_scalar_element<std::int32_t>("index", idx < 0 ? 4 : idx));
                if (e.find("unreliable")) r.elements.push_back(make_scalar_element<std::int32_t>("unreliable", 1));
                return r;
            }
            case MessageEntryType::PipeDisconnectReq: return r;
            case MessageEntryType::PipePacket:
            case MessageEntryType::PipePacketRet: packets.push_back(e); return std::nullopt;
            default: return std::nullopt;
        }
    };
    Got<PipeEndpointHandle> ep;
    f.c.pipe_connect("svc", "samples", -1, f.t0, ep.cb());
    f.run();
    auto info = f.c.pipe_info(ep.value());
    REQUIRE(info);
    CHECK(info->index == 4);
    CHECK_FALSE(info->unreliable);
    int packet_calls = 0;
    std::vector<std::uint32_t> acks;
    std::optional<RRError> closed;
    REQUIRE(f.c.set_pipe_handlers(ep.value(), {[&](PipeEndpointHandle) { ++packet_calls; },
                                               [&](PipeEndpointHandle, std::uint32_t n) { acks.push_back(n); },
                                               [&](PipeEndpointHandle, const RRError& e) { closed = e; }}));

    // Sending: numbers 1, 2; requestack when asked; element named by the index.
    REQUIRE(f.c.pipe_send(ep.value(), Value::array<double>({1, 2}), f.t0).value() == 1);
    REQUIRE(f.c.set_pipe_request_ack(ep.value(), true));
    REQUIRE(f.c.pipe_send(ep.value(), Value::array<double>({3}), f.t0).value() == 2);
    CHECK(f.c.pipe_send(ep.value(), Value("x"), f.t0).error().type == MessageErrorType::DataTypeMismatch);
    f.run();
    REQUIRE(packets.size() == 2);
    const auto& p1 = packets[0].elements.at(0);
    CHECK(p1.name == "4");
    CHECK_FALSE(p1.number.has_value());
    CHECK(p1.type == DataTypes::dictionary_t);
    std::uint32_t n = 0;
    REQUIRE(read_scalar(*p1.find("packetnumber"), n));
    CHECK(n == 1);
    CHECK(p1.find("requestack") == nullptr);
    CHECK(packets[1].elements.at(0).find("requestack") != nullptr);

    // Receiving: packets 2 then 1 arrive out of order, both asking for acks; delivery is in order.
    auto packet = [&](std::uint32_t number, double x, bool ack) {
        MessageElement d;
        d.name = "4";
        d.type = DataTypes::dictionary_t;
        d.elements.push_back(make_scalar_element("packetnumber", number));
        d.elements.push_back(make_array_element<double>("packet", std::vector<double>{x}));
        if (ack) d.elements.push_back(make_scalar_element<std::uint32_t>("requestack", 1));
        return d;
    };
    MessageEntry in;
    in.entry_type = MessageEntryType::PipePacket;
    in.service_path = "svc";
    in.member_name = "samples";
    in.elements.push_back(packet(2, 20, true));
    f.s.send(in, f.t0);
    f.run();
    CHECK(f.c.pipe_available(ep.value()) == 0);  // waits for packet 1
    in.elements = {packet(1, 10, true)};
    f.s.send(in, f.t0);
    f.run();
    CHECK(packet_calls == 1);
    REQUIRE(f.c.pipe_available(ep.value()) == 2);
    CHECK(*f.c.pipe_receive(ep.value()) == Value::array<double>({10}));
    CHECK(*f.c.pipe_receive(ep.value()) == Value::array<double>({20}));
    CHECK_FALSE(f.c.pipe_receive(ep.value()));
    auto sent_acks = std::count_if(packets.begin(), packets.end(), [](const MessageEntry& e) { return e.entry_type == MessageEntryType::PipePacketRet; });
    CHECK(sent_acks == 2);
    const auto& ack = packets.back().elements.at(0);
    CHECK(ack.number == 4);
    REQUIRE(read_scalar(ack, n));
    CHECK(n == 1);

    // Acks from the service.
    MessageEntry ret;
    ret.entry_type = MessageEntryType::PipePacketRet;
    ret.service_path = "svc";
    ret.member_name = "samples";
    auto a = make_scalar_element<std::uint32_t>("", 2);
    a.number = 4;
    ret.elements.push_back(a);
    f.s.send(ret, f.t0);
    f.run();
    CHECK(acks == std::vector<std::uint32_t>{2});

    // Closed by the service.
    MessageEntry pc;
    pc.entry_type = MessageEntryType::PipeClosed;
    pc.service_path = "svc";
    pc.member_name = "samples";
    pc.elements.push_back(make_scalar_element<std::int32_t>("index", 4));
    f.s.send(pc, f.t0);
    f.run();
    REQUIRE(closed);
    CHECK(f.c.pipe_info(ep.value())->closed);
    CHECK(f.c.pipe_send(ep.value(), Value::array<double>({1}), f.t0).error().type == MessageErrorType::InvalidOperation);
    Got<void> release;
    const auto disconnects = f.s.of_type(MessageEntryType::PipeDisconnectReq).size();
    f.c.pipe_close(ep.value(), f.t0, release.cb());
    release.ok();
    f.run();
    CHECK(f.s.of_type(MessageEntryType::PipeDisconnectReq).size() == disconnects);  // nothing sent

    SECTION("readonly pipes refuse to send; unreliable ones mark their packets") {
        Got<PipeEndpointHandle> ro, un;
        f.c.pipe_connect("svc", "ro_pipe", 2, f.t0, ro.cb());
        f.c.pipe_connect("svc", "chat", -1, f.t0, un.cb());
        f.run();
        CHECK(f.c.pipe_send(ro.value(), Value::scalar(std::int32_t{1}), f.t0).error().type == MessageErrorType::ReadOnlyMember);
        CHECK(f.c.pipe_info(un.value())->unreliable);
        REQUIRE(f.c.pipe_send(un.value(), Value("hi"), f.t0));
        f.run();
        CHECK(packets.back().metadata == "unreliable\n");
        auto reqs = f.s.of_type(MessageEntryType::PipeConnectReq);
        CHECK(reqs.back().find("unreliable") != nullptr);
        Got<void> closed_ok;
        f.c.pipe_close(ro.value(), f.t0, closed_ok.cb());
        f.run();
        closed_ok.ok();
        CHECK(f.s.of_type(MessageEntryType::PipeDisconnectReq).size() == disconnects + 1);
    }
    SECTION("packets before the PipeConnectRet are kept for the new endpoint") {
        // Hold the connect answer, deliver a packet for the index first.
        std::optional<MessageEntry> held;
        auto script = f.s.script;
        f.s.script = [&](const MessageEntry& e) -> std::optional<MessageEntry> {
            if (e.entry_type == MessageEntryType::PipeConnectReq) {
                auto r = reply_to(e);
                r.elements.push_back(make_scalar_element<std::int32_t>("index", 8));
                held = r;
                return std::nullopt;
            }
            return script(e);
        };
        Got<PipeEndpointHandle> ep2;
        f.c.pipe_connect("svc", "samples", -1, f.t0, ep2.cb());
        f.run();
        REQUIRE(held);
        MessageEntry early = in;
        auto d = packet(1, 99, false);
        d.name = "8";
        early.elements = {d};
        f.s.send(early, f.t0);
        f.s.send(*held, f.t0);
        f.run();
        REQUIRE(ep2.value());
        CHECK(f.c.pipe_available(ep2.value()) == 1);
        CHECK(*f.c.pipe_receive(ep2.value()) == Value::array<double>({99}));
    }
}

TEST_CASE("wires: values with time stamps, older dropped, out values stamped, direction, peek/poke, lifespan, closed") {
    Fixture f;
    std::vector<MessageEntry> out_packets;
    f.s.script = [&](const MessageEntry& e) -> std::optional<MessageEntry> {
        auto r = reply_to(e);
        switch (e.entry_type) {
            case MessageEntryType::WireConnectReq:
            case MessageEntryType::WireDisconnectReq:
            case MessageEntryType::WirePokeOutValueReq: return r;
            case MessageEntryType::WirePeekInValueReq:
                r.elements.push_back(pack_timespec(TimeSpec{1700000000, 5}, "packettime"));
                r.elements.push_back(point_element("packet", 7, 8));
                return r;
            case MessageEntryType::WirePeekOutValueReq: return error_reply(e, make_error(MessageErrorType::ValueNotSet, "none"));
            case MessageEntryType::WirePacket: out_packets.push_back(e); return std::nullopt;
            default: return std::nullopt;
        }
    };
    Got<WireConnectionHandle> w;
    f.c.wire_connect("svc", "pose", f.t0, w.cb());
    f.run();
    REQUIRE(w.value());
    Got<WireConnectionHandle> again;
    f.c.wire_connect("svc", "pose", f.t0, again.cb());
    CHECK(again.error().type == MessageErrorType::InvalidOperation);
    CHECK(f.c.wire_in_value(w.value(), f.t0).error().type == MessageErrorType::ValueNotSet);

    std::vector<WireValue> values;
    std::optional<RRError> closed;
    REQUIRE(f.c.set_wire_handlers(w.value(), {[&](WireConnectionHandle, const WireValue& v) { values.push_back(v); },
                                              [&](WireConnectionHandle, const RRError& e) { closed = e; }}));
    auto wire_packet = [&](TimeSpec ts, double x) {
        MessageEntry e;
        e.entry_type = MessageEntryType::WirePacket;
        e.service_path = "svc";
        e.member_name = "pose";
        e.metadata = "unreliable\n";
        e.elements.push_back(pack_timespec(ts, "packettime"));
        e.elements.push_back(point_element("packet", x, 0));
        return e;
    };
    f.s.send(wire_packet({100, 0}, 1), f.t0);
    f.s.send(wire_packet({99, 999999999}, 2), f.t0);  // older: dropped
    f.s.send(wire_packet({100, 1}, 3), f.t0 + 5ms);
    pump(f.c, f.s, f.t0 + 5ms);
    REQUIRE(values.size() == 2);
    CHECK(values[0].value == point(1, 0));
    CHECK(values[1].value == point(3, 0));
    CHECK(values[1].timestamp == TimeSpec{100, 1});
    auto in = f.c.wire_in_value(w.value(), f.t0 + 10ms);
    REQUIRE(in);
    CHECK(in->value == point(3, 0));
    CHECK(in->local_time == f.t0 + 5ms);
    REQUIRE(f.c.set_wire_lifespans(w.value(), 10, -1));
    CHECK(f.c.wire_in_value(w.value(), f.t0 + 10ms));
    CHECK(f.c.wire_in_value(w.value(), f.t0 + 20ms).error().type == MessageErrorType::ValueNotSet);

    // OutValue: stamped with the wall clock given, made strictly increasing.
    REQUIRE(f.c.wire_set_out_value(w.value(), point(5, 5), TimeSpec{200, 0}, f.t0));
    REQUIRE(f.c.wire_set_out_value(w.value(), point(6, 6), TimeSpec{150, 0}, f.t0));  // clock went back
    CHECK(f.c.wire_set_out_value(w.value(), Value::scalar(1.0), TimeSpec{300, 0}, f.t0).error().type ==
          MessageErrorType::DataTypeMismatch);
    f.run();
    REQUIRE(out_packets.size() == 2);
    CHECK(out_packets[0].metadata == "unreliable\n");
    CHECK(unpack_timespec(*out_packets[0].find("packettime")).value() == TimeSpec{200, 0});
    CHECK(unpack_timespec(*out_packets[1].find("packettime")).value() == TimeSpec{200, 1});
    CHECK(f.c.wire_out_value(w.value(), f.t0).value().value == point(6, 6));

    Got<WireValue> peek_in, peek_out;
    Got<void> poke;
    f.c.wire_peek_in_value("svc", "pose", f.t0, peek_in.cb());
    f.c.wire_peek_out_value("svc", "pose", f.t0, peek_out.cb());
    f.c.wire_poke_out_value("svc", "pose", point(1, 2), TimeSpec{400, 0}, f.t0, poke.cb());
    f.run();
    CHECK(peek_in.value().value == point(7, 8));
    CHECK(peek_in.value().timestamp == TimeSpec{1700000000, 5});
    CHECK(peek_out.error().type == MessageErrorType::ValueNotSet);
    poke.ok();
    auto pokes = f.s.of_type(MessageEntryType::WirePokeOutValueReq);
    REQUIRE(pokes.size() == 1);
    CHECK(unpack_timespec(*pokes[0].find("packettime")).value() == TimeSpec{400, 0});

    // Direction.
    Got<WireConnectionHandle> ro, wo;
    f.c.wire_connect("svc", "ro_wire", f.t0, ro.cb());
    f.c.wire_connect("svc", "wo_wire", f.t0, wo.cb());
    f.run();
    CHECK(f.c.wire_set_out_value(ro.value(), Value::scalar(std::int32_t{1}), TimeSpec{1, 0}, f.t0).error().type ==
          MessageErrorType::ReadOnlyMember);
    CHECK(f.c.wire_in_value(wo.value(), f.t0).error().type == MessageErrorType::WriteOnlyMember);
    Got<void> poke_ro;
    Got<WireValue> peek_wo;
    f.c.wire_poke_out_value("svc", "ro_wire", Value::scalar(std::int32_t{1}), TimeSpec{1, 0}, f.t0, poke_ro.cb());
    f.c.wire_peek_in_value("svc", "wo_wire", f.t0, peek_wo.cb());
    CHECK(poke_ro.error().type == MessageErrorType::ReadOnlyMember);
    CHECK(peek_wo.error().type == MessageErrorType::WriteOnlyMember);

    // Closed by the service.
    MessageEntry wc;
    wc.entry_type = MessageEntryType::WireClosed;
    wc.service_path = "svc";
    wc.member_name = "pose";
    f.s.send(wc, f.t0);
    f.run();
    REQUIRE(closed);
    CHECK(f.c.wire_info(w.value())->closed);
    CHECK(f.c.wire_set_out_value(w.value(), point(0, 0), TimeSpec{500, 0}, f.t0).error().type == MessageErrorType::InvalidOperation);
    Got<void> release;
    f.c.wire_close(w.value(), f.t0, release.cb());
    release.ok();
    Got<WireConnectionHandle> reconnect;
    f.c.wire_connect("svc", "pose", f.t0, reconnect.cb());
    f.run();
    CHECK(reconnect.value());
}

namespace {

// A memory service: `buf` (double[100] = i*0.5) and `grid` (int32[4,5] = k, column-major), with a
// MaxTransferSize of 64 bytes so that transfers are split.
struct MemoryScript {
    std::vector<double> buf;
    std::vector<std::int32_t> grid;
    std::vector<MessageEntry> requests;
    MemoryScript() {
        for (int i = 0; i < 100; ++i) buf.push_back(i * 0.5);
        for (int k = 0; k < 20; ++k) grid.push_back(k);
    }
    std::optional<MessageEntry> operator()(const MessageEntry& e) {
        requests.push_back(e);
        auto r = reply_to(e);
        if (e.entry_type == MessageEntryType::MemoryGetParam) {
            auto p = read_string(*e.find("parameter"));
            if (p == "MaxTransferSize") r.elements.push_back(make_scalar_element<std::uint32_t>("return", 64));
            else if (p == "Length") r.elements.push_back(make_scalar_element<std::uint64_t>("return", buf.size()));
            else if (p == "DimCount") r.elements.push_back(make_scalar_element<std::uint64_t>("return", 2));
            else r.elements.push_back(make_array_element<std::uint64_t>("return", std::vector<std::uint64_t>{4, 5}));
            return r;
        }
        auto pos = read_array<std::uint64_t>(*e.find("memorypos"));
        auto count = read_array<std::uint64_t>(*e.find("count"));
        if (e.member_name == "buf") {
            if (e.entry_type == MessageEntryType::MemoryRead) {
                std::vector<double> d(buf.begin() + pos[0], buf.begin() + pos[0] + count[0]);
                r.elements.push_back(make_array_element<double>("data", d));
            } else {
                auto d = read_array<double>(*e.find("data"));
                REQUIRE(d.size() == count[0]);
                std::copy(d.begin(), d.end(), buf.begin() + pos[0]);
                r.entry_type = MessageEntryType::MemoryReadRet;  // as CORE answers writes
            }
            return r;
        }
        // grid: 4 x 5, column-major
        std::size_t n = count[0] * count[1];
        if (e.entry_type == MessageEntryType::MemoryRead) {
            std::vector<std::int32_t> d;
            for (std::uint64_t j = 0; j < count[1]; ++j)
                for (std::uint64_t i = 0; i < count[0]; ++i) d.push_back(grid[(pos[0] + i) + 4 * (pos[1] + j)]);
            MessageElement md;
            md.name = "data";
            md.type = DataTypes::multidimarray_t;
            md.elements.push_back(make_array_element<std::uint32_t>("dims", std::vector<std::uint32_t>{std::uint32_t(count[0]), std::uint32_t(count[1])}));
            md.elements.push_back(make_array_element<std::int32_t>("array", d));
            r.elements.push_back(md);
        } else {
            const auto* md = e.find("data");
            auto d = read_array<std::int32_t>(*md->find("array"));
            REQUIRE(d.size() == n);
            std::size_t t = 0;
            for (std::uint64_t j = 0; j < count[1]; ++j)
                for (std::uint64_t i = 0; i < count[0]; ++i) grid[(pos[0] + i) + 4 * (pos[1] + j)] = d[t++];
        }
        return r;
    }
};

}  // namespace

TEST_CASE("memories: parameters, reads and writes split at MaxTransferSize and reassembled") {
    Fixture f;
    auto mem = std::make_shared<MemoryScript>();
    f.s.script = [mem](const MessageEntry& e) { return (*mem)(e); };

    Got<std::uint64_t> len, dimcount;
    Got<std::vector<std::uint64_t>> dims;
    f.c.memory_length("svc", "buf", f.t0, len.cb());
    f.c.memory_dim_count("svc", "grid", f.t0, dimcount.cb());
    f.c.memory_dimensions("svc", "grid", f.t0, dims.cb());
    f.run();
    CHECK(len.value() == 100);
    CHECK(dimcount.value() == 2);
    CHECK(dims.value() == std::vector<std::uint64_t>{4, 5});

    // 20 doubles at 8 per transfer (64 bytes): 3 reads.
    Got<Value> r;
    mem->requests.clear();
    f.c.memory_read("svc", "buf", 10, 20, f.t0, r.cb());
    f.run();
    std::vector<double> want;
    for (int i = 10; i < 30; ++i) want.push_back(i * 0.5);
    CHECK(r.value() == Value::array<double>(std::span<const double>(want)));
    auto reads = std::count_if(mem->requests.begin(), mem->requests.end(),
                               [](const MessageEntry& e) { return e.entry_type == MessageEntryType::MemoryRead; });
    CHECK(reads == 3);

    // A single-transfer read keeps the received bytes (zero-copy view).
    Got<Value> small;
    f.c.memory_read("svc", "buf", 0, 4, f.t0, small.cb());
    f.run();
    CHECK(small.value().get_if<NumericArray>()->is_view());

    // 10 doubles written in 2 transfers.
    std::vector<double> w(10, -1.0);
    Got<void> wr;
    f.c.memory_write("svc", "buf", 50, Value::array<double>(std::span<const double>(w)), f.t0, wr.cb());
    f.run();
    wr.ok();
    for (int i = 50; i < 60; ++i) CHECK(mem->buf[i] == -1.0);
    CHECK(mem->buf[60] == 30.0);

    // Multi-dim: a 4x5 int32 read is 80 bytes: split along the last dimension and reassembled.
    Got<Value> g;
    mem->requests.clear();
    f.c.memory_read("svc", "grid", {0, 0}, {4, 5}, f.t0, g.cb());
    f.run();
    std::vector<std::int32_t> all;
    for (int k = 0; k < 20; ++k) all.push_back(k);
    CHECK(g.value() == Value(MultiDimArray{{4, 5}, NumericArray::from<std::int32_t>(std::span<const std::int32_t>(all))}));
    CHECK(std::count_if(mem->requests.begin(), mem->requests.end(),
                        [](const MessageEntry& e) { return e.entry_type == MessageEntryType::MemoryRead; }) > 1);

    // A 3x5 block write (60 bytes... fits) and a 4x5 write (split).
    std::vector<std::int32_t> block(20, 0);
    for (int k = 0; k < 20; ++k) block[k] = 100 + k;
    Got<void> gw;
    f.c.memory_write("svc", "grid", {0, 0}, Value(MultiDimArray{{4, 5}, NumericArray::from<std::int32_t>(std::span<const std::int32_t>(block))}),
                     f.t0, gw.cb());
    f.run();
    gw.ok();
    CHECK(mem->grid == block);
    Got<Value> sub;
    f.c.memory_read("svc", "grid", {1, 2}, {2, 2}, f.t0, sub.cb());
    f.run();
    CHECK(sub.value() == Value(MultiDimArray{{2, 2}, NumericArray::from<std::int32_t>({109, 110, 113, 114})}));

    // Local errors.
    Got<Value> wrong;
    f.c.memory_read("svc", "grid", 0, 1, f.t0, wrong.cb());
    CHECK(wrong.error().type == MessageErrorType::InvalidOperation);
    Got<void> wrong_type;
    f.c.memory_write("svc", "buf", 0, Value::array<std::int32_t>({1}), f.t0, wrong_type.cb());
    CHECK(wrong_type.error().type == MessageErrorType::DataTypeMismatch);
}

TEST_CASE("an unanswered request times out after the request timeout") {
    Fixture f;
    f.s.script = [](const MessageEntry&) { return std::optional<MessageEntry>(); };
    Got<Value> slow;
    f.c.call("svc", "slow", {}, f.t0, slow.cb());
    f.run();
    CHECK_FALSE(slow.ready());
    REQUIRE(f.c.next_deadline());
    // keep the transport alive with heartbeats up to 14 s, then pass the 15 s request deadline
    for (auto t : {5s, 10s, 14s}) {
        f.c.on_timer(f.t0 + t);
        f.s.stream.on_timer(f.t0 + t);
        pump(f.c, f.s, f.t0 + t);
    }
    CHECK_FALSE(slow.ready());
    f.c.on_timer(f.t0 + 15s + 1ms);
    CHECK(slow.error().type == MessageErrorType::RequestTimeout);
    CHECK(f.c.is_connected());
}

TEST_CASE("losing the connection fails pending requests and closes pipes and wires") {
    Fixture f;
    f.s.script = [&](const MessageEntry& e) -> std::optional<MessageEntry> {
        auto r = reply_to(e);
        if (e.entry_type == MessageEntryType::PipeConnectReq) {
            r.elements.push_back(make_scalar_element<std::int32_t>("index", 0));
            return r;
        }
        if (e.entry_type == MessageEntryType::WireConnectReq) return r;
        return std::nullopt;
    };
    Got<PipeEndpointHandle> ep;
    Got<WireConnectionHandle> w;
    f.c.pipe_connect("svc", "samples", -1, f.t0, ep.cb());
    f.c.wire_connect("svc", "pose", f.t0, w.cb());
    f.run();
    std::optional<RRError> pipe_closed, wire_closed, session_closed;
    REQUIRE(f.c.set_pipe_handlers(ep.value(), {nullptr, nullptr, [&](PipeEndpointHandle, const RRError& e) { pipe_closed = e; }}));
    REQUIRE(f.c.set_wire_handlers(w.value(), {nullptr, [&](WireConnectionHandle, const RRError& e) { wire_closed = e; }}));
    f.c.set_closed_handler([&](const RRError& e) { session_closed = e; });
    Got<Value> pending;
    f.c.property_get("svc", "speed", f.t0, pending.cb());
    f.run();
    CHECK_FALSE(pending.ready());
    f.c.on_transport_closed(make_error(MessageErrorType::ConnectionError, "socket reset"));
    CHECK(pending.error().type == MessageErrorType::ConnectionError);
    REQUIRE(pipe_closed);
    REQUIRE(wire_closed);
    REQUIRE(session_closed);
    CHECK(f.c.is_closed());
    Got<Value> after;
    f.c.property_get("svc", "speed", f.t0, after.cb());
    CHECK(after.error().type == MessageErrorType::ConnectionError);
}

TEST_CASE("monitor lock repeats MonitorContinueEnter while the service says Continue") {
    Fixture f;
    int continues = 0;
    f.s.script = [&](const MessageEntry& e) -> std::optional<MessageEntry> {
        if (e.entry_type != MessageEntryType::ClientSessionOpReq) return std::nullopt;
        auto r = reply_to(e);
        std::string answer = "OK";
        if (e.member_name == "MonitorEnter") {
            std::int32_t t = 0;
            REQUIRE(read_scalar(*e.find("timeout"), t));
            CHECK(t == 250);
            answer = "Continue";
        } else if (e.member_name == "MonitorContinueEnter" && ++continues < 2) {
            answer = "Continue";
        }
        r.elements.push_back(make_string_element("return", answer));
        return r;
    };
    Got<void> enter, exit;
    f.c.monitor_enter("svc", 250, f.t0, enter.cb());
    f.run();
    enter.ok();
    CHECK(continues == 2);
    f.c.monitor_exit("svc", f.t0, exit.cb());
    f.run();
    exit.ok();
    CHECK(f.s.of_type(MessageEntryType::ClientSessionOpReq).back().member_name == "MonitorExit");
}
