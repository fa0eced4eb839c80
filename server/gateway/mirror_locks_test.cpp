// Object and monitor locks held at the gateway for an `auth: shared` device (docs/security.md "auth:
// shared"): the mirror decides lock operations with its own table, keyed by the client's gateway
// session and gateway user, and refuses other sessions' requests before they reach the device, with
// the answers our ObjectService gives. The device is an ObjectService without logins (the gateway's
// one session); clients are RawClients logged in as gateway users.
#include <catch2/catch.hpp>

#include "core/value/timespec.hpp"
#include "server/gateway/auth/gateway_auth.hpp"
#include "server/gateway/auth/mirror_access.hpp"
#include "server/gateway/device_mirror.hpp"
#include "server/gateway/mirror_service.hpp"
#include "server/node/test_node.hpp"
#include "server/service/object_service_fixture.hpp"
#include "test/support/eventually.hpp"

using namespace rr;
using namespace rr::server;
using namespace rr::server::gateway;
using namespace rr::server::testing;
using namespace std::chrono_literals;
using rr::testing::eventually;

// Named, not anonymous: the TSan preset builds the tests as unity files.
namespace mirror_locks_test {

constexpr const char* kArmDef = R"(service example.armtest

stdver 0.10

object Arm
    property double pos
    property double free [nolock]
    property double readable [nolockread]
    objref Gripper gripper
    wire double w
end

object Gripper
    property double width
end
)";

struct ArmDevice {
    std::shared_ptr<ServiceObject> root, gripper;
    std::shared_ptr<ObjectService> service;
    std::shared_ptr<Node> node = test_node("arm.node");
    std::uint16_t port = 0;

    ArmDevice() {
        auto types = ServiceTypes::create({kArmDef});
        REQUIRE(types);
        root = ServiceObject::create(*types, "example.armtest.Arm").value();
        gripper = ServiceObject::create(*types, "example.armtest.Gripper").value();
        for (const char* p : {"pos", "free", "readable"}) REQUIRE(root->set_property_value(p, Value::scalar(1.5)));
        REQUIRE(gripper->set_property_value("width", Value::scalar(0.25)));
        REQUIRE(root->set_objref("gripper", [this](const SessionRef&, const ObjRefIndex&) -> Result<std::shared_ptr<ServiceObject>> {
            return gripper;
        }));
        service = ObjectService::create("arm", root).value();
        REQUIRE(node->register_service(service));
        port = *listen_tcp(node, "127.0.0.1", 0);
    }
    ~ArmDevice() {
        node->shutdown();
        service->shutdown();
    }
};

/// The gateway in front of ArmDevice as device "dev" (auth: shared), with gateway users when `users`.
struct LockGateway {
    ArmDevice device;
    std::shared_ptr<Node> node = test_node("gateway.node");
    std::shared_ptr<DeviceMirror> mirror;
    std::uint16_t port = 0;

    explicit LockGateway(bool users = true) {
        DeviceConfig cfg;
        cfg.name = "dev";
        cfg.url = "rr+tcp://127.0.0.1:" + std::to_string(device.port) + "/?service=arm";
        mirror = DeviceMirror::create(node, cfg).value();
        if (users) {
            auth::GatewayAuthSettings s;
            s.users.add_user("alice", "a", {"operator", "objectlock"});
            s.users.add_user("bob", "b", {"operator", "objectlock"});
            s.users.add_user("carol", "c", {"operator"});
            s.users.add_user("root", "r", {"operator", "objectlockoverride"});
            s.users.add_user("mallory", "m", {});                        // logs in, may do nothing
            s.users.add_user("victor", "v", {"viewer", "objectlock"});   // reads, no lock
            s.users.add_user("gus", "g", {"gripper", "objectlock"});     // locks the gripper only
            auto policy = std::make_shared<auth::AccessPolicy>();
            auth::AccessRule all;
            all.devices = {"*"};
            all.members = {"*"};
            all.read = all.write = all.call = all.lock = true;
            policy->add_role("operator", {all});
            auth::AccessRule read;
            read.devices = {"*"};
            read.members = {"*"};
            read.read = true;
            policy->add_role("viewer", {read});
            auth::AccessRule gripper_lock;  // for `lock`, members name objects by relative service path
            gripper_lock.devices = {"dev"};
            gripper_lock.members = {"gripper"};
            gripper_lock.lock = true;
            policy->add_role("gripper", {read, gripper_lock});
            s.policy = policy;
            mirror->mirror_service()->set_access(auth::MirrorAccess(std::make_shared<auth::GatewayAuth>(std::move(s)), "dev"));
        }
        mirror->start();
        port = *listen_tcp(node, "127.0.0.1", 0);
        REQUIRE(eventually([&] { return mirror->status().state == DeviceState::connected; }));
    }
    ~LockGateway() {
        mirror->stop();
        node->shutdown();
    }

    TestClient connect(const char* user = nullptr, const char* password = nullptr) const {
        RawClientOptions o;
        if (user) {
            o.username = user;
            o.password = password;
        }
        TestClient c;
        std::promise<Result<std::shared_ptr<RawClient>>> p;
        auto url = parse_connection_url("rr+tcp://127.0.0.1:" + std::to_string(port) + "/?service=dev");
        REQUIRE(url);
        RawClient::connect(node->io_context().get_executor(), *url, std::move(o),
                           [inbox = c.inbox](MessageEntry&& e) { inbox->push(std::move(e)); }, {},
                           [&](Result<std::shared_ptr<RawClient>> r) { p.set_value(std::move(r)); });
        auto f = p.get_future();
        REQUIRE(f.wait_for(30s) == std::future_status::ready);
        auto r = f.get();
        INFO((r ? std::string() : r.error().message));
        REQUIRE(r);
        c.raw = *r;
        return c;
    }

    /// (path, user, kind) of every lock the device's status lists, sorted.
    std::vector<std::tuple<std::string, std::string, std::string>> locks() const {
        std::vector<std::tuple<std::string, std::string, std::string>> out;
        for (const auto& l : mirror->status().locks) out.emplace_back(l.path, l.username, l.kind);
        std::sort(out.begin(), out.end());
        return out;
    }
};

MessageEntry shared_lock_op(const char* name, std::string path = "dev") { return req(MessageEntryType::ClientSessionOpReq, name, std::move(path)); }

MessageEntry enter_op(std::int32_t timeout, std::string path = "dev") {
    auto m = shared_lock_op("MonitorEnter", std::move(path));
    m.elements.push_back(make_scalar_element<std::int32_t>("timeout", timeout));
    return m;
}

MessageEntry get_req(const char* member, std::string path = "dev") { return req(MessageEntryType::PropertyGetReq, member, std::move(path)); }

MessageEntry set_req(const char* member, double v) {
    auto e = req(MessageEntryType::PropertySetReq, member, "dev");
    e.elements.push_back(make_scalar_element("value", v));
    return e;
}

std::string op_result(const MessageEntry& e) {
    const auto* el = e.find("return");
    REQUIRE(el);
    return std::string(read_string(*el));
}

using HeldLocks = std::vector<std::tuple<std::string, std::string, std::string>>;

}  // namespace mirror_locks_test
using namespace mirror_locks_test;

TEST_CASE("auth shared: a user lock at the gateway refuses other users on the object and its children") {
    LockGateway gw;
    auto a = gw.connect("alice", "a");
    auto a2 = gw.connect("alice", "a");
    auto b = gw.connect("bob", "b");
    auto c = gw.connect("carol", "c");

    auto no_priv = c.error(shared_lock_op("RequestObjectLock"));
    CHECK(no_priv.type == MessageErrorType::ObjectLockedError);
    CHECK(no_priv.message == "User does not have object locking privileges");

    CHECK(op_result(a.ok(shared_lock_op("RequestObjectLock"))) == "OK");
    CHECK(gw.locks() == HeldLocks{{"dev", "alice", "user"}});
    auto refused = b.error(get_req("pos"));
    CHECK(refused.type == MessageErrorType::ObjectLockedError);
    CHECK(refused.message == "Object locked by alice");
    CHECK(b.error(get_req("width", "dev.gripper")).message == "Object locked by alice");  // a child
    CHECK(b.error(set_req("pos", 2.0)).type == MessageErrorType::ObjectLockedError);
    CHECK(scalar_of<double>(a.ok(get_req("pos")), "value") == 1.5);
    CHECK(scalar_of<double>(a2.ok(get_req("width", "dev.gripper")), "value") == 0.25);  // alice's other session
    a2.ok(set_req("pos", 2.0));
    CHECK(gw.device.root->property_value("pos").value().as<double>().value() == 2.0);  // reached the device

    CHECK(b.error(shared_lock_op("RequestObjectLock", "dev.gripper")).message == "Object already locked");
    CHECK(b.error(shared_lock_op("ReleaseObjectLock")).message == "Service locked by user alice");
    CHECK(a.error(shared_lock_op("ReleaseObjectLock", "dev.gripper")).message == "Cannot release inherited lock");
    CHECK(op_result(a2.ok(shared_lock_op("ReleaseObjectLock"))) == "OK");  // the user's other session may release it
    CHECK(gw.locks().empty());
    CHECK(scalar_of<double>(b.ok(get_req("pos")), "value") == 2.0);

    // A child locked alone; the device's answer for an object that does not exist, nothing locked.
    CHECK(op_result(b.ok(shared_lock_op("RequestObjectLock", "dev.gripper"))) == "OK");
    CHECK(scalar_of<double>(a.ok(get_req("pos")), "value") == 2.0);
    CHECK(a.error(get_req("width", "dev.gripper")).message == "Object locked by bob");
    CHECK(a.error(shared_lock_op("RequestObjectLock")).message == "Object already locked");  // a lock below
    CHECK(a.error(shared_lock_op("RequestObjectLock", "dev.nothing")).type != MessageErrorType::None);
    CHECK(gw.locks() == HeldLocks{{"dev.gripper", "bob", "user"}});

    // objectlockoverride releases another user's lock.
    auto r = gw.connect("root", "r");
    CHECK(r.error(get_req("width", "dev.gripper")).type == MessageErrorType::ObjectLockedError);
    CHECK(op_result(r.ok(shared_lock_op("ReleaseObjectLock", "dev.gripper"))) == "OK");
    CHECK(scalar_of<double>(a.ok(get_req("width", "dev.gripper")), "value") == 0.25);
    CHECK(b.error(shared_lock_op("ReleaseClientObjectLock")).message == "Invalid command");
}

TEST_CASE("auth shared: a client lock binds the user's other sessions, closing sessions release locks") {
    LockGateway gw;
    auto a = gw.connect("alice", "a");
    auto a2 = gw.connect("alice", "a");
    auto b = gw.connect("bob", "b");

    CHECK(op_result(a.ok(shared_lock_op("RequestClientObjectLock"))) == "OK");
    CHECK(gw.locks() == HeldLocks{{"dev", "alice", "client"}});
    CHECK(scalar_of<double>(a.ok(get_req("pos")), "value") == 1.5);
    CHECK(a2.error(get_req("pos")).message == "Object locked by alice");
    CHECK(b.error(get_req("pos")).type == MessageErrorType::ObjectLockedError);
    a.raw->close();  // the client lock goes with its session
    CHECK(eventually([&] { return gw.locks().empty(); }));
    CHECK(scalar_of<double>(b.ok(get_req("pos")), "value") == 1.5);

    // A user lock stays while another gateway session of its user is open, and goes with the last.
    CHECK(op_result(a2.ok(shared_lock_op("RequestObjectLock"))) == "OK");
    auto a3 = gw.connect("alice", "a");
    a2.raw->close();
    CHECK(eventually([&] { return gw.mirror->status().downstream_sessions == 2; }));
    CHECK(b.error(get_req("pos")).type == MessageErrorType::ObjectLockedError);
    CHECK(gw.locks() == HeldLocks{{"dev", "alice", "user"}});
    a3.raw->close();
    CHECK(eventually([&] { return gw.locks().empty(); }));
    CHECK(scalar_of<double>(b.ok(get_req("pos")), "value") == 1.5);
}

TEST_CASE("auth shared: a monitor at the gateway refuses other sessions and is handed over on MonitorExit") {
    LockGateway gw;
    auto a = gw.connect("alice", "a");
    auto b = gw.connect("bob", "b");
    CHECK(op_result(a.ok(enter_op(-1))) == "OK");
    CHECK(gw.locks() == HeldLocks{{"dev", "alice", "monitor"}});
    CHECK(a.error(enter_op(-1)).message == "Already acquiring or acquired monitor lock");
    CHECK(scalar_of<double>(a.ok(get_req("pos")), "value") == 1.5);
    auto blocked = b.error(get_req("pos"));
    CHECK(blocked.type == MessageErrorType::InvalidOperation);
    CHECK(blocked.message == "Object is currently monitor locked. Use MonitorEnter to obtain monitor lock");
    CHECK(scalar_of<double>(b.ok(get_req("width", "dev.gripper")), "value") == 0.25);  // monitors are per object
    CHECK(b.error(shared_lock_op("MonitorExit")).message == "Not monitor locked");

    // b waits at the gateway; a's MonitorExit answers it "OK" well before the 5 s "Continue".
    std::promise<Result<MessageEntry>> waiting;
    b.raw->request(enter_op(-1), [&](Result<MessageEntry> r) { waiting.set_value(std::move(r)); });
    auto fut = waiting.get_future();
    CHECK(fut.wait_for(300ms) == std::future_status::timeout);
    CHECK(op_result(a.ok(shared_lock_op("MonitorExit"))) == "OK");
    REQUIRE(fut.wait_for(rr::testing::kHangBound) == std::future_status::ready);
    auto got = fut.get();
    REQUIRE(got);
    CHECK(op_result(*got) == "OK");  // handed over, not the "Continue" of 5 s later
    CHECK(gw.locks() == HeldLocks{{"dev", "bob", "monitor"}});
    CHECK(a.error(get_req("pos")).type == MessageErrorType::InvalidOperation);
    CHECK(a.error(enter_op(200)).type == MessageErrorType::RequestTimeout);

    b.raw->close();  // the holder's session goes: its monitor with it
    CHECK(eventually([&] { return gw.locks().empty(); }));
    CHECK(scalar_of<double>(a.ok(get_req("pos")), "value") == 1.5);
}

TEST_CASE("auth shared: locks need the roles' `lock`, a login without it is refused every lock operation") {
    LockGateway gw;
    auto a = gw.connect("alice", "a");
    auto m = gw.connect("mallory", "m");
    auto v = gw.connect("victor", "v");
    auto g = gw.connect("gus", "g");

    // A login with no role: every lock operation refused before it reaches the locks, nothing held, and
    // the operator's requests are not blocked (the issue: a role-less MonitorEnter blocked everyone).
    for (const char* op : {"MonitorEnter", "MonitorContinueEnter", "MonitorExit", "RequestObjectLock", "RequestClientObjectLock",
                           "ReleaseObjectLock", "ReleaseClientObjectLock"}) {
        INFO(op);
        auto e = std::string(op) == "MonitorEnter" ? enter_op(-1) : shared_lock_op(op);
        auto refused = m.error(std::move(e));
        CHECK(refused.type == MessageErrorType::PermissionDenied);
        CHECK(refused.message == "user mallory may not lock the root object of dev");
    }
    CHECK(m.error(enter_op(-1, "dev.gripper")).message == "user mallory may not lock object gripper of dev");
    CHECK(gw.locks().empty());
    CHECK(scalar_of<double>(a.ok(get_req("pos")), "value") == 1.5);
    a.ok(set_req("pos", 2.0));
    CHECK(gw.device.root->property_value("pos").value().as<double>().value() == 2.0);

    // read without lock (the objectlock privilege alone is not enough through the gateway).
    CHECK(v.error(shared_lock_op("RequestObjectLock")).message == "user victor may not lock the root object of dev");
    CHECK(v.error(enter_op(-1)).type == MessageErrorType::PermissionDenied);
    CHECK(scalar_of<double>(v.ok(get_req("pos")), "value") == 2.0);

    // `lock` on one object: that object only (rule members name objects for lock).
    CHECK(g.error(shared_lock_op("RequestObjectLock")).message == "user gus may not lock the root object of dev");
    CHECK(op_result(g.ok(shared_lock_op("RequestObjectLock", "dev.gripper"))) == "OK");
    CHECK(gw.locks() == HeldLocks{{"dev.gripper", "gus", "user"}});
    CHECK(a.error(get_req("width", "dev.gripper")).message == "Object locked by gus");
    CHECK(op_result(g.ok(shared_lock_op("ReleaseObjectLock", "dev.gripper"))) == "OK");
    CHECK(op_result(g.ok(enter_op(-1, "dev.gripper"))) == "OK");
    CHECK(a.error(get_req("width", "dev.gripper")).type == MessageErrorType::InvalidOperation);
    CHECK(op_result(g.ok(shared_lock_op("MonitorExit", "dev.gripper"))) == "OK");
    CHECK(scalar_of<double>(a.ok(get_req("width", "dev.gripper")), "value") == 0.25);
}

TEST_CASE("auth shared: [nolock] and [nolockread] members pass gateway-held object locks, not monitors") {
    LockGateway gw;
    auto a = gw.connect("alice", "a");
    auto b = gw.connect("bob", "b");
    CHECK(op_result(a.ok(shared_lock_op("RequestObjectLock"))) == "OK");
    CHECK(b.error(get_req("pos")).type == MessageErrorType::ObjectLockedError);
    CHECK(scalar_of<double>(b.ok(get_req("free")), "value") == 1.5);
    b.ok(set_req("free", 3.0));
    CHECK(gw.device.root->property_value("free").value().as<double>().value() == 3.0);
    CHECK(scalar_of<double>(b.ok(get_req("readable")), "value") == 1.5);
    CHECK(b.error(set_req("readable", 3.0)).type == MessageErrorType::ObjectLockedError);
    CHECK(op_result(a.ok(shared_lock_op("ReleaseObjectLock"))) == "OK");

    CHECK(op_result(a.ok(enter_op(-1))) == "OK");
    CHECK(b.error(get_req("free")).type == MessageErrorType::InvalidOperation);
    CHECK(op_result(a.ok(shared_lock_op("MonitorExit"))) == "OK");
}

TEST_CASE("auth shared: wire packets on a connection opened before the lock pass, new connections are refused") {
    LockGateway gw;
    auto a = gw.connect("alice", "a");
    auto b = gw.connect("bob", "b");
    auto c = gw.connect("bob", "b");
    b.ok(req(MessageEntryType::WireConnectReq, "w", "dev"));
    CHECK(op_result(a.ok(shared_lock_op("RequestObjectLock"))) == "OK");
    CHECK(c.error(req(MessageEntryType::WireConnectReq, "w", "dev")).message == "Object locked by alice");

    std::int32_t ns = 0;
    auto packet = [&ns](double v) {  // each newer than the last: a wire keeps only newer values
        auto p = req(MessageEntryType::WirePacket, "w", "dev");
        p.elements.push_back(pack_timespec(TimeSpec{1700000000, ++ns}, "packettime"));
        p.elements.push_back(make_scalar_element("packet", v));
        return p;
    };
    auto wire = gw.device.root->wire("w").value();
    auto in_value = [&] {
        auto v = wire->in_value();
        auto d = v ? v->value.as<double>() : Result<double>(fail(MessageErrorType::ValueNotSet, "none"));
        return d ? *d : -1.0;
    };
    b.send(packet(4.5));  // connected before the lock: passes, as CORE lets packets through
    CHECK(eventually([&] { return in_value() == 4.5; }));
    c.send(packet(9.0));  // never connected this wire: dropped at the gateway
    std::this_thread::sleep_for(300ms);
    CHECK(in_value() == 4.5);
    b.send(packet(5.5));
    CHECK(eventually([&] { return in_value() == 5.5; }));
}

TEST_CASE("auth shared: JSON API requests act as their gateway user, with no session of their own") {
    LockGateway gw;
    auto svc = gw.mirror->mirror_service();
    auto a = gw.connect("alice", "a");
    CHECK(op_result(a.ok(shared_lock_op("RequestObjectLock"))) == "OK");
    CHECK(svc->check_api_request("dev", "alice", false));
    CHECK(svc->check_api_request("dev.gripper", "alice", false));
    CHECK(svc->check_api_request("dev", "bob", false).error().message == "Object locked by alice");
    CHECK(svc->check_api_request("dev", "", false).error().type == MessageErrorType::ObjectLockedError);
    CHECK(svc->check_api_request("dev", "bob", true));  // a [nolock] member
    CHECK(op_result(a.ok(shared_lock_op("ReleaseObjectLock"))) == "OK");

    CHECK(op_result(a.ok(shared_lock_op("RequestClientObjectLock"))) == "OK");  // the locking session only
    CHECK(svc->check_api_request("dev", "alice", false).error().type == MessageErrorType::ObjectLockedError);
    CHECK(op_result(a.ok(shared_lock_op("ReleaseObjectLock"))) == "OK");

    CHECK(op_result(a.ok(enter_op(-1))) == "OK");  // a monitor is another session's
    CHECK(svc->check_api_request("dev", "alice", true).error().type == MessageErrorType::InvalidOperation);
    CHECK(op_result(a.ok(shared_lock_op("MonitorExit"))) == "OK");
    CHECK(svc->check_api_request("dev", "bob", false));
}

TEST_CASE("auth shared without gateway users: object locks need a login, monitors do not") {
    LockGateway gw(false);
    auto a = gw.connect();
    auto b = gw.connect();
    auto refused = a.error(shared_lock_op("RequestObjectLock"));
    CHECK(refused.type == MessageErrorType::PermissionDenied);
    CHECK(refused.message == "User must be authenticated to lock object");
    CHECK(a.error(shared_lock_op("RequestClientObjectLock")).type == MessageErrorType::PermissionDenied);
    CHECK(op_result(a.ok(enter_op(-1))) == "OK");
    CHECK(gw.locks() == HeldLocks{{"dev", "", "monitor"}});
    CHECK(b.error(get_req("pos")).type == MessageErrorType::InvalidOperation);
    CHECK(scalar_of<double>(a.ok(get_req("pos")), "value") == 1.5);
    CHECK(op_result(a.ok(shared_lock_op("MonitorExit"))) == "OK");
    CHECK(scalar_of<double>(b.ok(get_req("pos")), "value") == 1.5);
}
