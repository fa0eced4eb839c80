// MotionGuard with a recording stand-in for the device: what each path's requests become (a clamped
// timeout, a refusal naming the holder, a stop that ends every hold), what the guard sends when a client
// goes away or a command stream goes silent (generator aborts, then halt() and command_mode = halt, on
// the client's passthrough session first), and when it turns the holder's liveness probe on and off.
#include <catch2/catch.hpp>

#include <thread>

#include <boost/asio/io_context.hpp>

#include "base/message/error_entry.hpp"
#include "core/session/elements.hpp"
#include "server/gateway/motion_guard.hpp"

using namespace rr;
using namespace rr::server::gateway;
using namespace std::chrono_literals;

namespace {

struct FakeDevice {
    struct Sent {
        MessageEntry entry;
        std::uint32_t session;
    };
    std::vector<Sent> sent;
    MotionGuard::DeviceRequest request() {
        return [this](MessageEntry e, std::uint32_t session, std::function<void(Result<MessageEntry>)> done) {
            sent.push_back({e, session});
            MessageEntry reply;
            reply.entry_type = static_cast<MessageEntryType>(static_cast<int>(e.entry_type) + 1);
            done(std::move(reply));
        };
    }
};

struct Probe {
    std::vector<std::optional<std::chrono::milliseconds>> calls;
};

MotionClient client(std::string key, std::string user, Probe* probe = nullptr, std::uint32_t session = 0) {
    MotionClient c;
    c.key = std::move(key);
    c.user = std::move(user);
    c.description = "test client";
    c.device_session = session;
    if (probe) c.liveness = [probe](std::optional<std::chrono::milliseconds> t) { probe->calls.push_back(t); };
    return c;
}

MessageEntry function_call(std::string member, std::vector<MessageElement> args = {}) {
    MessageEntry e;
    e.entry_type = MessageEntryType::FunctionCallReq;
    e.service_path = "arm";
    e.member_name = std::move(member);
    e.elements = std::move(args);
    return e;
}

MessageEntry jog(double timeout) {
    return function_call("jog_joint", {make_array_element<double>("joint_velocity", std::vector<double>{0.1, 0, 0}),
                              make_scalar_element<double>("timeout", timeout), make_scalar_element<bool>("wait", false)});
}

MessageEntry reply_with_index(std::int32_t index) {
    MessageEntry r;
    r.entry_type = MessageEntryType::FunctionCallRes;
    r.elements.push_back(make_scalar_element<std::int32_t>("index", index));
    return r;
}

struct Fixture {
    boost::asio::io_context io;
    FakeDevice device;
    std::shared_ptr<MotionGuard> guard;
    explicit Fixture(std::chrono::milliseconds bound = 500ms) {
        MotionSafety s;
        s.hold_to_run_max = bound;
        guard = std::make_shared<MotionGuard>(io.get_executor(), "arm", s, device.request());
        guard->set_root(ObjectTypeInfo{std::string(kStandardRobotType), {}}, nullptr);
    }
    std::vector<std::string> sent_members() const {
        std::vector<std::string> out;
        for (const auto& s : device.sent) out.push_back(s.entry.member_name + "@" + std::to_string(s.session));
        return out;
    }
    /// Runs the io_context until `done` or 20 s (a bound on a hang, not the expected time).
    template <class Pred>
    bool run_until(Pred done) {
        const auto deadline = std::chrono::steady_clock::now() + 20s;
        while (!done() && std::chrono::steady_clock::now() < deadline) {
            io.restart();
            io.run_for(10ms);
        }
        return done();
    }
};

}  // namespace

TEST_CASE("motion guard: a 60 s jog is clamped to the bound and holds the robot for its caller only", "[motion]") {
    Fixture f;
    auto alice = client("ws:1", "alice");
    auto bob = client("rr:2", "bob");
    auto e = jog(60);
    auto t = f.guard->admit(alice, e);
    REQUIRE(t);
    CHECK(t->kind == MotionGuard::Ticket::Kind::timed);
    double timeout = 0;
    REQUIRE(read_scalar(*e.find("timeout"), timeout));
    CHECK(timeout == Approx(0.5));
    auto e2 = jog(0.15);
    auto refused = f.guard->admit(bob, e2);
    REQUIRE_FALSE(refused);
    CHECK(refused.error().type == MessageErrorType::ObjectLockedError);
    CHECK(refused.error().message.find("held by alice (test client)") != std::string::npos);
    REQUIRE(f.guard->holder());
    CHECK(f.guard->holder()->user == "alice");
    // Other members, other objects and read requests pass untouched.
    auto enable = function_call("enable");
    CHECK(f.guard->admit(bob, enable)->kind == MotionGuard::Ticket::Kind::pass);
    auto below = jog(60);
    below.service_path = "arm.tool";
    CHECK(f.guard->admit(bob, below)->kind == MotionGuard::Ticket::Kind::pass);
    REQUIRE(read_scalar(*below.find("timeout"), timeout));
    CHECK(timeout == 60);
    CHECK(f.device.sent.empty());
}

TEST_CASE("motion guard: a stop passes, ends every hold, and is recognised for the lock override", "[motion]") {
    Fixture f;
    auto alice = client("ws:1", "alice");
    auto bob = client("rr:2", "bob");
    auto e = jog(0.4);
    REQUIRE(f.guard->admit(alice, e));
    auto halt = function_call("halt");
    CHECK(f.guard->is_stop(halt));
    auto t = f.guard->admit(bob, halt);
    REQUIRE(t);
    CHECK(t->kind == MotionGuard::Ticket::Kind::stop);
    CHECK_FALSE(f.guard->holder());
    auto e2 = jog(0.4);
    CHECK(f.guard->admit(bob, e2));

    MessageEntry mode;
    mode.entry_type = MessageEntryType::PropertySetReq;
    mode.service_path = "arm";
    mode.member_name = "command_mode";
    mode.elements.push_back(make_scalar_element<std::int32_t>("value", 0));
    CHECK(f.guard->is_stop(mode));
    CHECK(f.guard->admit(alice, mode)->kind == MotionGuard::Ticket::Kind::stop);
    mode.elements[0] = make_scalar_element<std::int32_t>("value", 1);  // jog mode: not a stop
    CHECK_FALSE(f.guard->is_stop(mode));
    CHECK(f.guard->admit(alice, mode)->kind == MotionGuard::Ticket::Kind::pass);
}

TEST_CASE("motion guard: jog_freespace without wait is ended by halt and command_mode when its client goes", "[motion]") {
    Fixture f;
    Probe probe;
    auto alice = client("rr:5", "alice", &probe);
    auto e = function_call("jog_freespace", {make_array_element<double>("joint_position", std::vector<double>{0.1, 0, 0}),
                                    make_array_element<double>("max_velocity", std::vector<double>{0.01, 0.01, 0.01}),
                                    make_scalar_element<bool>("wait", false)});
    auto t = f.guard->admit(alice, e);
    REQUIRE(t);
    CHECK(t->kind == MotionGuard::Ticket::Kind::untimed);
    CHECK_FALSE(t->waits);
    // The probe starts with the motion, at the bound.
    REQUIRE(probe.calls.size() == 1);
    CHECK(probe.calls[0] == std::optional<std::chrono::milliseconds>(500ms));
    MessageEntry ok;
    ok.entry_type = MessageEntryType::FunctionCallRes;
    f.guard->on_reply(alice, *t, ok);
    REQUIRE(f.guard->holder());  // still moving: wait false
    bool done = false;
    f.guard->client_gone("rr:5", [&] { done = true; });
    CHECK(done);
    CHECK(f.sent_members() == std::vector<std::string>{"halt@0", "command_mode@0"});
    CHECK(f.guard->stops_sent() == 1);
    CHECK_FALSE(f.guard->holder());
    REQUIRE(probe.calls.size() == 2);
    CHECK_FALSE(probe.calls[1].has_value());
}

TEST_CASE("motion guard: a tool's close() holds until halt(), and is halted when its client goes", "[motion]") {
    Fixture f;
    f.guard->set_root(ObjectTypeInfo{std::string(kStandardToolType), {}}, nullptr);
    auto alice = client("ws:1", "alice");
    auto bob = client("rr:2", "bob");
    auto close = function_call("close");
    auto t = f.guard->admit(alice, close);
    REQUIRE(t);
    MessageEntry ok;
    ok.entry_type = MessageEntryType::FunctionCallRes;
    f.guard->on_reply(alice, *t, ok);
    REQUIRE(f.guard->holder());  // the fingers keep moving after the call returns
    auto open = function_call("open");
    CHECK_FALSE(f.guard->admit(bob, open));  // another client may not move the tool meanwhile
    auto halt = function_call("halt");
    CHECK(f.guard->admit(bob, halt)->kind == MotionGuard::Ticket::Kind::stop);
    CHECK_FALSE(f.guard->holder());

    auto set = function_call("setf_command", {make_scalar_element<double>("command", 0.06)});
    auto t2 = f.guard->admit(alice, set);
    REQUIRE(t2);
    f.guard->on_reply(alice, *t2, ok);
    bool done = false;
    f.guard->client_gone("ws:1", [&] { done = true; });
    CHECK(done);
    CHECK(f.sent_members() == std::vector<std::string>{"halt@0"});
    CHECK_FALSE(f.guard->holder());
}

TEST_CASE("motion guard: a call that waits holds until its answer, a failed call holds nothing", "[motion]") {
    Fixture f;
    Probe probe;
    auto alice = client("rr:5", "alice", &probe);
    auto e = function_call("jog_freespace", {make_scalar_element<bool>("wait", true)});
    auto t = f.guard->admit(alice, e);
    REQUIRE(t);
    CHECK(t->waits);
    REQUIRE(f.guard->holder());
    f.guard->on_reply(alice, *t, MessageEntry{});
    CHECK_FALSE(f.guard->holder());
    REQUIRE(probe.calls.size() == 2);  // on, then off

    auto e2 = function_call("jog_freespace", {make_scalar_element<bool>("wait", false)});
    auto t2 = f.guard->admit(alice, e2);
    REQUIRE(t2);
    f.guard->on_reply(alice, *t2, fail(MessageErrorType::InvalidOperation, "Robot not in jog mode"));
    CHECK_FALSE(f.guard->holder());
    f.guard->client_gone("rr:5");
    CHECK(f.device.sent.empty());  // nothing was moving: no stop
}

TEST_CASE("motion guard: a trajectory generator is aborted, then the robot halted, when its client goes", "[motion]") {
    Fixture f;
    auto alice = client("rr:8", "alice", nullptr, /*passthrough session*/ 8);
    auto e = function_call("execute_trajectory");
    auto t = f.guard->admit(alice, e);
    REQUIRE(t);
    CHECK(t->kind == MotionGuard::Ticket::Kind::generator);
    f.guard->on_reply(alice, *t, reply_with_index(3));
    f.guard->client_gone("rr:8");
    REQUIRE(f.device.sent.size() == 5);
    const auto& abort = f.device.sent[0];
    CHECK(abort.entry.entry_type == MessageEntryType::GeneratorNextReq);
    CHECK(abort.entry.member_name == "execute_trajectory");
    CHECK(abort.entry.error == MessageErrorType::OperationAborted);
    CHECK(abort.session == 8);
    std::int32_t index = -1;
    REQUIRE(read_scalar(*abort.entry.find("index"), index));
    CHECK(index == 3);
    // On a passthrough device the stops go on the client's own session first (its locks), then the shared one.
    CHECK(f.sent_members() ==
          std::vector<std::string>{"execute_trajectory@8", "halt@8", "halt@0", "command_mode@8", "command_mode@0"});
}

TEST_CASE("motion guard: a generator that finished needs nothing when its client goes", "[motion]") {
    Fixture f;
    auto alice = client("rr:8", "alice");
    auto e = function_call("execute_trajectory");
    auto t = f.guard->admit(alice, e);
    f.guard->on_reply(alice, *t, reply_with_index(4));
    MessageEntry next;
    next.entry_type = MessageEntryType::GeneratorNextReq;
    next.service_path = "arm";
    next.member_name = "execute_trajectory";
    next.elements.push_back(make_scalar_element<std::int32_t>("index", 4));
    auto tn = f.guard->admit(alice, next);
    REQUIRE(tn);
    CHECK(tn->kind == MotionGuard::Ticket::Kind::generator_next);
    MessageEntry stop_iteration;
    set_entry_error(stop_iteration, make_error(MessageErrorType::StopIteration, ""));
    f.guard->on_reply(alice, *tn, stop_iteration);
    CHECK_FALSE(f.guard->holder());
    f.guard->client_gone("rr:8");
    CHECK(f.device.sent.empty());
}

TEST_CASE("motion guard: a command stream silent for the bound stops the robot, another sender is refused meanwhile", "[motion]") {
    Fixture f(200ms);
    Probe probe;
    auto carol = client("rr:3", "carol", &probe);
    auto dave = client("ws:4", "dave");
    MessageEntry packet;
    packet.entry_type = MessageEntryType::WirePacket;
    packet.service_path = "arm";
    packet.member_name = "position_command";
    REQUIRE(f.guard->admit(carol, packet));
    auto refused = f.guard->admit(dave, packet);
    REQUIRE_FALSE(refused);
    CHECK(refused.error().message.find("carol") != std::string::npos);
    MessageEntry connect = packet;
    connect.entry_type = MessageEntryType::WireConnectReq;
    CHECK_FALSE(f.guard->admit(dave, connect));
    CHECK(f.guard->admit(carol, connect));
    REQUIRE(f.run_until([&] { return f.device.sent.size() >= 2; }));
    CHECK(f.sent_members() == std::vector<std::string>{"halt@0", "command_mode@0"});
    CHECK_FALSE(f.guard->holder());
    REQUIRE(probe.calls.size() == 2);
    CHECK(probe.calls[0] == std::optional<std::chrono::milliseconds>(200ms));
    CHECK_FALSE(probe.calls[1].has_value());
    CHECK(f.guard->admit(dave, packet));
}

TEST_CASE("motion guard: a device that is no robot and has nothing configured is not guarded", "[motion]") {
    boost::asio::io_context io;
    FakeDevice device;
    auto guard = std::make_shared<MotionGuard>(io.get_executor(), "create", MotionSafety{}, device.request());
    guard->set_root(ObjectTypeInfo{"experimental.create.Create", {}}, nullptr);
    auto e = function_call("Drive");
    e.service_path = "create";
    CHECK_FALSE(guard->concerns(e));
    CHECK(guard->admit(client("a", ""), e)->kind == MotionGuard::Ticket::Kind::pass);
    // Before the device's first connect nothing is known: everything passes.
    auto fresh = std::make_shared<MotionGuard>(io.get_executor(), "arm", MotionSafety{}, device.request());
    auto j = jog(60);
    CHECK_FALSE(fresh->concerns(j));
}

TEST_CASE("motion guard: a hold-to-run call refused by a lock or the device holds nothing", "[motion]") {
    Fixture f;
    auto alice = client("ws:1", "alice");
    auto bob = client("rr:2", "bob");
    auto e = jog(0.4);
    auto t = f.guard->admit(bob, e);
    REQUIRE(t);
    REQUIRE(f.guard->holder());
    f.guard->on_reply(bob, *t, fail(MessageErrorType::ObjectLockedError, "Object locked by alice"));
    CHECK_FALSE(f.guard->holder());
    auto e2 = jog(0.4);
    auto ta = f.guard->admit(alice, e2);
    REQUIRE(ta);
    f.guard->on_reply(alice, *ta, MessageEntry{});
    // A renewal the device refuses leaves the earlier call's hold as it was.
    auto e3 = jog(0.4);
    auto tb = f.guard->admit(alice, e3);
    REQUIRE(tb);
    f.guard->on_reply(alice, *tb, fail(MessageErrorType::InvalidOperation, "Robot not in jog mode"));
    REQUIRE(f.guard->holder());
    CHECK(f.guard->holder()->user == "alice");
}

TEST_CASE("motion guard: the log tells when a hold starts and when another client takes over after it lapsed", "[motion]") {
    Fixture f(50ms);
    std::vector<std::string> events;
    f.guard->set_event_listener([&](const std::string& what) { events.push_back(what); });
    auto alice = client("ws:1", "alice");
    auto bob = client("rr:2", "bob");
    auto e = jog(0.05);
    REQUIRE(f.guard->admit(alice, e));
    auto renew = jog(0.05);
    REQUIRE(f.guard->admit(alice, renew));  // a renewal starts nothing
    auto taken = [&] {
        std::vector<std::string> out;
        for (const auto& s : events)
            if (s.find(" taken by ") != std::string::npos) out.push_back(s);
        return out;
    };
    REQUIRE(taken() == std::vector<std::string>{"jog_joint: motion of arm taken by alice (test client)"});
    auto early = jog(0.05);
    REQUIRE_FALSE(f.guard->admit(bob, early));
    CHECK(taken().size() == 1);
    std::this_thread::sleep_for(120ms);  // past alice's 50 ms hold: it has lapsed
    auto later = jog(0.05);
    REQUIRE(f.guard->admit(bob, later));
    CHECK(taken().back() == "jog_joint: motion of arm taken by bob (test client)");
}
