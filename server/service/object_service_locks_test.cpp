// Object and monitor locks of ObjectService over the wire (RawClient sessions on a loopback node):
// privileges, other users and other sessions refused, children covered, release rules, release when a
// session closes, monitor hand-over. The bookkeeping alone: object_locks_test.cpp.
#include "server/service/object_service_fixture.hpp"
#include "test/support/eventually.hpp"

#include <thread>

using namespace rr;
using namespace rr::server;
using namespace rr::server::testing;

namespace {

RawClientOptions login(const char* user, const char* password) {
    RawClientOptions o;
    o.username = user;
    o.password = password;
    return o;
}

MessageEntry lock_op(const char* op, std::string path = kTestService) {
    return req(MessageEntryType::ClientSessionOpReq, op, std::move(path));
}

std::string returned(const MessageEntry& e) {
    const auto* el = e.find("return");
    REQUIRE(el);
    return std::string(read_string(*el));
}

using rr::testing::eventually;

struct LockFixture {
    std::shared_ptr<ServiceObject> sub;
    ServiceFixture f{[this](ServiceFixture& f) {
        sub = ServiceObject::create(f.types, "example.objtest.Sub").value();
        REQUIRE(sub->set_property_value("n", Value::scalar<std::int32_t>(5)));
        REQUIRE(f.root->set_property_value("value", Value::scalar(1.5)));
        REQUIRE(f.root->set_objref("sub", [this](const SessionRef&, const ObjRefIndex&) -> Result<std::shared_ptr<ServiceObject>> {
            return sub;
        }));
    }};
    LockFixture() {
        PasswordTable users;
        users.add_user("alice", "a", {"objectlock"});
        users.add_user("bob", "b", {"objectlock"});
        users.add_user("root", "r", {"objectlockoverride"});
        users.add_user("eve", "e");
        f.service->set_users(std::move(users));
    }
};

MessageEntry get_value() { return req(MessageEntryType::PropertyGetReq, "value"); }
MessageEntry get_n() { return req(MessageEntryType::PropertyGetReq, "n", std::string(kTestService) + ".sub"); }

}  // namespace

TEST_CASE("object locks: user lock blocks other users on the object and its children, not the user's other sessions") {
    LockFixture lf;
    auto a = lf.f.connect(login("alice", "a"));
    auto a2 = lf.f.connect(login("alice", "a"));
    auto b = lf.f.connect(login("bob", "b"));
    auto e = lf.f.connect(login("eve", "e"));

    auto no_priv = e.error(lock_op("RequestObjectLock"));
    CHECK(no_priv.type == MessageErrorType::ObjectLockedError);
    CHECK(no_priv.message == "User does not have object locking privileges");

    CHECK(returned(a.ok(lock_op("RequestObjectLock"))) == "OK");
    CHECK(lf.f.service->lock_holder(std::string(kTestService) + ".sub")->username == "alice");
    auto refused = b.error(get_value());
    CHECK(refused.type == MessageErrorType::ObjectLockedError);
    CHECK(refused.message == "Object locked by alice");
    CHECK(b.error(get_n()).type == MessageErrorType::ObjectLockedError);  // a child of the locked object
    CHECK(b.error(lock_op("RequestObjectLock", std::string(kTestService) + ".sub")).type == MessageErrorType::ObjectLockedError);
    CHECK(b.error(lock_op("ReleaseObjectLock")).message == "Service locked by user alice");
    CHECK(a.error(lock_op("ReleaseObjectLock", std::string(kTestService) + ".sub")).message == "Cannot release inherited lock");
    CHECK(scalar_of<double>(a.ok(get_value()), "value") == 1.5);
    CHECK(scalar_of<double>(a2.ok(get_value()), "value") == 1.5);  // the same user's other session
    CHECK(scalar_of<std::int32_t>(a2.ok(get_n()), "value") == 5);

    CHECK(returned(a.ok(lock_op("ReleaseObjectLock"))) == "OK");
    CHECK(scalar_of<double>(b.ok(get_value()), "value") == 1.5);
    CHECK(returned(b.ok(lock_op("ReleaseObjectLock"))) == "OK");  // nothing locked
    CHECK(b.error(lock_op("ReleaseClientObjectLock")).type == MessageErrorType::InvalidOperation);
    // No such object: the resolution error (MemberNotFound here), and nothing is locked.
    CHECK(b.error(lock_op("RequestObjectLock", std::string(kTestService) + ".nothing")).type == MessageErrorType::MemberNotFound);
    CHECK_FALSE(lf.f.service->lock_holder(std::string(kTestService) + ".nothing"));

    // objectlockoverride releases another user's lock.
    CHECK(returned(b.ok(lock_op("RequestObjectLock"))) == "OK");
    auto r = lf.f.connect(login("root", "r"));
    CHECK(r.error(get_value()).type == MessageErrorType::ObjectLockedError);
    CHECK(returned(r.ok(lock_op("ReleaseObjectLock"))) == "OK");
    CHECK(scalar_of<double>(a.ok(get_value()), "value") == 1.5);
}

TEST_CASE("object locks: client lock blocks the user's other sessions, closing sessions release locks") {
    LockFixture lf;
    auto a = lf.f.connect(login("alice", "a"));
    auto a2 = lf.f.connect(login("alice", "a"));
    auto b = lf.f.connect(login("bob", "b"));

    // Not logged in: PermissionDenied (CORE: "User must be authenticated to lock object").
    RawClientOptions none;
    CHECK_FALSE(lf.f.try_connect(none));  // the service requires a login anyway

    CHECK(returned(a.ok(lock_op("RequestClientObjectLock"))) == "OK");
    CHECK(scalar_of<double>(a.ok(get_value()), "value") == 1.5);
    CHECK(a2.error(get_value()).type == MessageErrorType::ObjectLockedError);
    CHECK(b.error(get_value()).type == MessageErrorType::ObjectLockedError);

    a.raw->close();  // the client lock goes with its session
    CHECK(eventually([&] { return !lf.f.service->lock_holder(kTestService); }));
    CHECK(scalar_of<double>(b.ok(get_value()), "value") == 1.5);

    // A user lock stays while another session of its user is open, and goes with the last one.
    CHECK(returned(a2.ok(lock_op("RequestObjectLock"))) == "OK");
    auto a3 = lf.f.connect(login("alice", "a"));
    a2.raw->close();
    std::this_thread::sleep_for(300ms);
    CHECK(b.error(get_value()).type == MessageErrorType::ObjectLockedError);
    a3.raw->close();
    CHECK(eventually([&] { return !lf.f.service->lock_holder(kTestService); }));
    CHECK(scalar_of<double>(b.ok(get_value()), "value") == 1.5);
}

TEST_CASE("object locks: monitor lock blocks other sessions and is handed over on MonitorExit") {
    LockFixture lf;
    auto a = lf.f.connect(login("alice", "a"));
    auto b = lf.f.connect(login("bob", "b"));
    auto enter = [](std::int32_t timeout) {
        auto m = lock_op("MonitorEnter");
        m.elements.push_back(make_scalar_element<std::int32_t>("timeout", timeout));
        return m;
    };
    CHECK(returned(a.ok(enter(-1))) == "OK");
    CHECK(a.error(enter(-1)).message == "Already acquiring or acquired monitor lock");
    CHECK(scalar_of<double>(a.ok(get_value()), "value") == 1.5);
    auto blocked = b.error(get_value());
    CHECK(blocked.type == MessageErrorType::InvalidOperation);
    CHECK(blocked.message == "Object is currently monitor locked. Use MonitorEnter to obtain monitor lock");
    CHECK(scalar_of<std::int32_t>(b.ok(get_n()), "value") == 5);  // monitors are per object

    // b waits; a's MonitorExit answers b's MonitorEnter "OK" well before the 5 s "Continue".
    std::promise<Result<MessageEntry>> waiting;
    b.raw->request(enter(-1), [&](Result<MessageEntry> r) { waiting.set_value(std::move(r)); });
    auto fut = waiting.get_future();
    CHECK(fut.wait_for(300ms) == std::future_status::timeout);
    CHECK(returned(a.ok(lock_op("MonitorExit"))) == "OK");
    REQUIRE(fut.wait_for(rr::testing::kHangBound) == std::future_status::ready);
    auto got = fut.get();
    REQUIRE(got);
    CHECK(returned(*got) == "OK");  // handed over, not the "Continue" of 5 s later
    CHECK(a.error(get_value()).type == MessageErrorType::InvalidOperation);

    // a waits with a short timeout: RequestTimeout.
    auto timed_out = a.error(enter(200));
    CHECK(timed_out.type == MessageErrorType::RequestTimeout);

    // A waiter that is not handed the monitor within 5 s hears "Continue", then asks again.
    std::promise<Result<MessageEntry>> cont;
    a.raw->request(enter(-1), [&](Result<MessageEntry> r) { cont.set_value(std::move(r)); });
    auto cf = cont.get_future();
    REQUIRE(cf.wait_for(rr::testing::kHangBound) == std::future_status::ready);
    auto c = cf.get();
    REQUIRE(c);
    CHECK(returned(*c) == "Continue");
    b.raw->close();  // the holder leaves: a gets the monitor
    CHECK(eventually([&] { return returned(a.ok(lock_op("MonitorContinueEnter"))) == "OK"; }));
    CHECK(scalar_of<double>(a.ok(get_value()), "value") == 1.5);
    CHECK(returned(a.ok(lock_op("MonitorExit"))) == "OK");
}

TEST_CASE("object locks: a MonitorEnter timeout past the 5 s Continue is answered when it passes, not 5 s later") {
    LockFixture lf;
    auto a = lf.f.connect(login("alice", "a"));
    auto b = lf.f.connect(login("bob", "b"));
    auto enter = [](std::int32_t timeout) {
        auto m = lock_op("MonitorEnter");
        m.elements.push_back(make_scalar_element<std::int32_t>("timeout", timeout));
        return m;
    };
    CHECK(returned(a.ok(enter(-1))) == "OK");
    const auto t0 = std::chrono::steady_clock::now();
    CHECK(returned(b.ok(enter(6500))) == "Continue");  // after kMonitorWait
    // The client asks again, as the official client does; the wait ends with the timeout (6.5 s after
    // the MonitorEnter), not at the next "Continue" (10 s). A bound on a hang, generous: 3 s over.
    auto timed_out = b.error(lock_op("MonitorContinueEnter"));
    const auto took = std::chrono::steady_clock::now() - t0;
    CHECK(timed_out.type == MessageErrorType::RequestTimeout);
    CHECK(timed_out.message == "Timed out waiting for the monitor lock");
    CHECK(took >= std::chrono::milliseconds(6500));
    CHECK(took < std::chrono::milliseconds(9500));
    CHECK(b.error(get_value()).type == MessageErrorType::InvalidOperation);  // a still holds it
    CHECK(returned(a.ok(lock_op("MonitorExit"))) == "OK");
}

TEST_CASE("object locks: members marked [nolock] / [nolockread] pass object locks, not monitor locks") {
    ServiceFixture f;
    auto types = ServiceTypes::create({"service example.nolocktest\n\nstdver 0.10\n\nobject Obj\n"
                                       "    property double plain\n"
                                       "    property double free [nolock]\n"
                                       "    property double readable [nolockread]\n"
                                       "end\n"});
    REQUIRE(types);
    auto root = ServiceObject::create(*types, "example.nolocktest.Obj").value();
    for (const char* p : {"plain", "free", "readable"}) REQUIRE(root->set_property_value(p, Value::scalar(2.0)));
    auto service = ObjectService::create("lk", root).value();
    PasswordTable users;
    users.add_user("alice", "a", {"objectlock"});
    users.add_user("bob", "b");
    service->set_users(std::move(users));
    REQUIRE(f.node->register_service(service));
    auto connect = [&](const char* user, const char* pw) {
        TestClient c;
        std::promise<Result<std::shared_ptr<RawClient>>> p;
        auto url = parse_connection_url("rr+tcp://127.0.0.1:" + std::to_string(f.port) + "/?service=lk");
        REQUIRE(url);
        RawClient::connect(f.node->io_context().get_executor(), *url, login(user, pw),
                           [inbox = c.inbox](MessageEntry&& e) { inbox->push(std::move(e)); }, {},
                           [&](Result<std::shared_ptr<RawClient>> r) { p.set_value(std::move(r)); });
        auto fut = p.get_future();
        REQUIRE(fut.wait_for(30s) == std::future_status::ready);
        auto r = fut.get();
        REQUIRE(r);
        c.raw = *r;
        return c;
    };
    auto a = connect("alice", "a");
    auto b = connect("bob", "b");
    auto get = [](const char* m) { return req(MessageEntryType::PropertyGetReq, m, "lk"); };
    auto set = [](const char* m) {
        auto e = req(MessageEntryType::PropertySetReq, m, "lk");
        e.elements.push_back(make_scalar_element("value", 3.0));
        return e;
    };
    CHECK(returned(a.ok(lock_op("RequestObjectLock", "lk"))) == "OK");
    CHECK(b.error(get("plain")).type == MessageErrorType::ObjectLockedError);
    CHECK(scalar_of<double>(b.ok(get("free")), "value") == 2.0);
    b.ok(set("free"));
    CHECK(scalar_of<double>(b.ok(get("readable")), "value") == 2.0);
    CHECK(b.error(set("readable")).type == MessageErrorType::ObjectLockedError);
    CHECK(returned(a.ok(lock_op("ReleaseObjectLock", "lk"))) == "OK");

    auto enter = lock_op("MonitorEnter", "lk");
    enter.elements.push_back(make_scalar_element<std::int32_t>("timeout", -1));
    CHECK(returned(a.ok(enter)) == "OK");
    CHECK(b.error(get("free")).type == MessageErrorType::InvalidOperation);
    CHECK(returned(a.ok(lock_op("MonitorExit", "lk"))) == "OK");
    a.raw->close();
    b.raw->close();
    service->shutdown();
}

TEST_CASE("object locks: a lock the service takes for a user blocks other sessions except [nolock] members") {
    LockFixture lf;
    auto& f = lf.f;
    const std::string sub_path = std::string(kTestService) + ".sub";
    CHECK(f.service->request_object_lock("elsewhere.sub", "server").error().type == MessageErrorType::InvalidArgument);
    CHECK(f.service->request_object_lock(std::string(kTestService) + "x", "server").error().type == MessageErrorType::InvalidArgument);
    REQUIRE(f.service->request_object_lock(sub_path, "server"));  // before any client resolved it
    CHECK(f.service->request_object_lock(sub_path, "other").error().type == MessageErrorType::ObjectLockedError);
    REQUIRE(f.service->lock_holder(sub_path));
    CHECK(f.service->lock_holder(sub_path)->username == "server");

    auto alice = f.connect(login("alice", "a"));
    auto e = alice.error(get_n());
    CHECK(e.type == MessageErrorType::ObjectLockedError);
    CHECK(e.message == "Object locked by server");
    alice.ok(get_value());  // the root is not covered
    // another user without override cannot release it; a user with objectlockoverride can
    CHECK(alice.error(lock_op("ReleaseObjectLock", sub_path)).type == MessageErrorType::ObjectLockedError);

    SECTION("released by the service") {
        REQUIRE(f.service->release_object_lock(sub_path));
        alice.ok(get_n());
        CHECK_FALSE(f.service->lock_holder(sub_path));
        REQUIRE(f.service->release_object_lock(sub_path));  // nothing held: OK
    }
    SECTION("released by a client with objectlockoverride") {
        auto root = f.connect(login("root", "r"));
        root.ok(lock_op("ReleaseObjectLock", sub_path));
        alice.ok(get_n());
    }
}
