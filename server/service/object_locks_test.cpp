// ObjectLocks bookkeeping (object_locks.hpp) with time fed by hand. The same rules over the wire,
// through ObjectService and two clients, are in object_service_test.cpp ("object locks: …") and
// against the official Python client in test/interop/locks_logins.py.
#include <catch2/catch.hpp>

#include "server/service/object_locks.hpp"
#include "server/service/service_locks.hpp"

using namespace rr;
using namespace rr::server;
using namespace std::chrono_literals;

TEST_CASE("object locks: covers() compares whole path segments") {
    CHECK(ObjectLocks::covers("svc", "svc"));
    CHECK(ObjectLocks::covers("svc", "svc.sub"));
    CHECK(ObjectLocks::covers("svc.subs", "svc.subs[2].leaf"));
    CHECK(ObjectLocks::covers("svc.subs[2]", "svc.subs[2].leaf"));
    CHECK_FALSE(ObjectLocks::covers("svc.child", "svc.child_by_int[1]"));
    CHECK_FALSE(ObjectLocks::covers("svc.sub", "svc"));
}

TEST_CASE("object locks: user lock, client lock, children, release rules") {
    ObjectLocks l;
    REQUIRE(l.lock("svc.sub", "alice", 0));
    // Covered: the object and its children; alice's sessions pass, others are refused.
    CHECK(l.check("svc.sub", "alice", 7));
    CHECK(l.check("svc.sub.leaf", "alice", 8));
    auto refused = l.check("svc.sub.leaf", "bob", 9);
    REQUIRE_FALSE(refused);
    CHECK(refused.error().type == MessageErrorType::ObjectLockedError);
    CHECK(refused.error().message == "Object locked by alice");
    CHECK_FALSE(l.check("svc.sub", "", 9));  // not logged in
    CHECK(l.check("svc", "bob", 9));          // the parent is not locked
    CHECK(l.check("svc.other", "bob", 9));

    // No second lock on, above or below a locked object (not even by the same user).
    CHECK(l.lock("svc.sub", "alice", 0).error().message == "Object already locked");
    CHECK(l.lock("svc.sub.leaf", "alice", 0).error().type == MessageErrorType::ObjectLockedError);
    CHECK(l.lock("svc", "bob", 0).error().type == MessageErrorType::ObjectLockedError);

    // Release: inherited, another user's (without / with override), nothing locked.
    CHECK(l.release("svc.sub.leaf", "alice", 7, false).error().message == "Cannot release inherited lock");
    CHECK(l.release("svc.sub", "bob", 9, false).error().message == "Service locked by user alice");
    CHECK(l.release("svc.other", "bob", 9, false));
    REQUIRE(l.release("svc.sub", "bob", 9, true));
    CHECK(l.lock_count() == 0);
    CHECK(l.check("svc.sub", "bob", 9));

    // Client lock: other sessions of the same user are refused too.
    REQUIRE(l.lock("svc", "alice", 7));
    CHECK(l.check("svc.sub", "alice", 7));
    CHECK(l.check("svc.sub", "alice", 8).error().type == MessageErrorType::ObjectLockedError);
    REQUIRE(l.holder("svc.sub"));
    CHECK(l.holder("svc.sub")->endpoint == 7);
    CHECK(l.holder("svc.sub")->path == "svc");
}

TEST_CASE("object locks: closing sessions release their locks") {
    ObjectLocks l;
    REQUIRE(l.lock("svc.a", "alice", 7));  // client lock of session 7
    REQUIRE(l.lock("svc.b", "alice", 0));  // user lock
    REQUIRE(l.lock("svc.c", "bob", 0));
    l.session_closed(8, "alice", false);  // another alice session, not her last
    CHECK(l.lock_count() == 3);
    l.session_closed(7, "alice", false);  // the client lock goes with its session
    CHECK_FALSE(l.holder("svc.a"));
    CHECK(l.holder("svc.b"));
    l.session_closed(9, "alice", true);  // alice's last session: her user lock goes
    CHECK_FALSE(l.holder("svc.b"));
    CHECK(l.holder("svc.c"));
}

TEST_CASE("object locks: monitor hand-over, refresh, idle expiry, waiter timeout, session close") {
    ObjectLocks l;
    std::vector<ObjectLocks::MonitorEvent> ev;
    const auto t0 = ObjectLocks::Clock::time_point{} + 1h;

    auto a = l.monitor_enter("svc", 1, -1, t0, ev);
    REQUIRE(a);
    CHECK(*a);
    CHECK(l.monitor_enter("svc", 1, -1, t0, ev).error().type == MessageErrorType::InvalidOperation);
    CHECK(l.monitor_check("svc", 1, t0, ev));
    auto blocked = l.monitor_check("svc", 2, t0, ev);
    REQUIRE_FALSE(blocked);
    CHECK(blocked.error().message == "Object is currently monitor locked. Use MonitorEnter to obtain monitor lock");
    CHECK(l.monitor_check("svc.sub", 2, t0, ev));  // monitors are per object

    auto b = l.monitor_enter("svc", 2, -1, t0, ev);
    REQUIRE(b);
    CHECK_FALSE(*b);
    auto c = l.monitor_enter("svc", 3, 5000, t0, ev);
    REQUIRE(c);
    CHECK_FALSE(*c);
    CHECK(l.monitor_continue("svc", 2, t0 + 1s, ev).value() == false);
    CHECK(l.monitor_exit("svc", 9, t0, ev).error().message == "Not monitor locked");

    // Exit hands the monitor to the first in line.
    REQUIRE(l.monitor_exit("svc", 1, t0 + 2s, ev));
    REQUIRE(ev.size() == 1);
    CHECK(ev[0].endpoint == 2);
    CHECK(ev[0].granted);
    ev.clear();
    CHECK(l.monitor_holder("svc") == 2);
    CHECK(l.monitor_continue("svc", 2, t0 + 2s, ev).value() == true);
    // 3 waits 5 s at most: dropped with RequestTimeout.
    CHECK(l.monitor_continue("svc", 3, t0 + 4s, ev).value() == false);
    auto late = l.monitor_continue("svc", 3, t0 + 6s, ev);
    REQUIRE_FALSE(late);
    CHECK(late.error().type == MessageErrorType::RequestTimeout);
    CHECK(l.monitor_continue("svc", 3, t0 + 6s, ev).error().message == "Not acquiring monitor lock");

    // Requests by the holder keep it; 30 s without any lose it.
    CHECK(l.monitor_check("svc", 2, t0 + 20s, ev));
    l.monitor_poll(t0 + 40s, ev);
    CHECK(l.monitor_holder("svc") == 2);
    l.monitor_poll(t0 + 51s, ev);
    CHECK(l.monitor_holder("svc") == 0);
    CHECK(l.monitor_check("svc", 4, t0 + 51s, ev));

    // A closing session gives the monitor to the next in line.
    REQUIRE(l.monitor_enter("svc", 5, -1, t0 + 60s, ev).value());
    REQUIRE_FALSE(l.monitor_enter("svc", 6, -1, t0 + 60s, ev).value());
    ev.clear();
    l.monitor_session_closed(5, t0 + 61s, ev);
    REQUIRE(ev.size() == 1);
    CHECK(ev[0].endpoint == 6);
    CHECK(l.monitor_holder("svc") == 6);
    CHECK(l.monitor_exit("svc", 6, t0 + 62s, ev));
    CHECK(l.monitor_exit("svc", 6, t0 + 62s, ev));  // nothing held: OK
    CHECK(l.monitor_holder("svc") == 0);
}

TEST_CASE("object locks: listings of locks and monitors, for who-holds-what answers") {
    ObjectLocks l;
    const auto t0 = ObjectLocks::Clock::time_point{} + 1000s;
    std::vector<ObjectLocks::MonitorEvent> ev;
    CHECK(l.empty());
    REQUIRE(l.lock("svc.b", "bob", 7));
    REQUIRE(l.lock("svc.a", "alice", 0));
    REQUIRE(l.monitor_enter("svc", 3, -1, t0, ev).value());
    CHECK_FALSE(l.empty());
    auto locks = l.locks();
    REQUIRE(locks.size() == 2);
    CHECK(locks[0].path == "svc.a");
    CHECK(locks[0].endpoint == 0);
    CHECK(locks[1].username == "bob");
    CHECK(locks[1].endpoint == 7);
    using Monitors = std::vector<std::pair<std::string, std::uint32_t>>;
    CHECK(l.monitor_holders(t0 + 29s) == Monitors{{"svc", 3}});
    CHECK(l.monitor_holders(t0 + 30s).empty());  // idle: gone at its next use
}

TEST_CASE("object locks: [nolock] passes every request, [nolockread] property and memory reads") {
    using T = MessageEntryType;
    CHECK(passes_object_locks({"nolock"}, T::PropertySetReq));
    CHECK(passes_object_locks({"readonly", "nolock"}, T::FunctionCallReq));
    CHECK(passes_object_locks({"nolockread"}, T::PropertyGetReq));
    CHECK(passes_object_locks({"nolockread"}, T::MemoryRead));
    CHECK(passes_object_locks({"nolockread"}, T::MemoryGetParam));
    CHECK_FALSE(passes_object_locks({"nolockread"}, T::PropertySetReq));
    CHECK_FALSE(passes_object_locks({"nolockread"}, T::MemoryWrite));
    CHECK_FALSE(passes_object_locks({}, T::PropertyGetReq));
    CHECK_FALSE(passes_object_locks({"readonly"}, T::PropertyGetReq));
}
