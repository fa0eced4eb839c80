#include "server/gateway/auth/access_policy.hpp"

#include <catch2/catch.hpp>

#include "server/gateway/auth/login_limiter.hpp"
#include "server/gateway/auth/mirror_access.hpp"

using namespace rr::server::gateway::auth;

TEST_CASE("gateway auth: glob patterns match literally except *") {
    CHECK(AccessPolicy::glob_match("*", ""));
    CHECK(AccessPolicy::glob_match("*", "Webcams[0].Capture"));
    CHECK(AccessPolicy::glob_match("Drive", "Drive"));
    CHECK_FALSE(AccessPolicy::glob_match("Drive", "DriveX"));
    CHECK(AccessPolicy::glob_match("Webcams[*].*", "Webcams[0].Capture"));
    CHECK_FALSE(AccessPolicy::glob_match("Webcams[*].*", "Webcams0.Capture"));
    CHECK(AccessPolicy::glob_match("*_sensor", "left_sensor"));
    CHECK_FALSE(AccessPolicy::glob_match("*_sensor", "left_sensorX"));
    CHECK(AccessPolicy::glob_match("a*b*c", "axxbyyc"));
    CHECK_FALSE(AccessPolicy::glob_match("a*b*c", "axxbyy"));
}

TEST_CASE("gateway auth: rules allow per role, device and member, and deny everything else") {
    AccessPolicy p;
    p.add_role("viewer", {AccessRule{{"*"}, {"*"}, true, false, false}});
    p.add_role("driver", {AccessRule{{"create"}, {"Drive", "StopAll"}, false, false, true},
                          AccessRule{{"create"}, {"DistanceTraveled"}, true, true, false}});
    CHECK(p.allows({"viewer"}, "create", "Bumpers", Operation::read));
    CHECK_FALSE(p.allows({"viewer"}, "create", "Bumpers", Operation::write));
    CHECK_FALSE(p.allows({"viewer"}, "create", "Drive", Operation::call));
    CHECK(p.allows({"driver"}, "create", "Drive", Operation::call));
    CHECK_FALSE(p.allows({"driver"}, "webcam", "Drive", Operation::call));
    CHECK_FALSE(p.allows({"driver"}, "create", "Drive", Operation::read));
    CHECK(p.allows({"driver"}, "create", "DistanceTraveled", Operation::write));
    CHECK(p.allows({"viewer", "driver"}, "create", "Drive", Operation::call));
    CHECK_FALSE(p.allows({}, "create", "Bumpers", Operation::read));
    CHECK_FALSE(p.allows({"nosuchrole"}, "create", "Bumpers", Operation::read));
    Principal who{"alice", {"driver"}, "password", std::make_shared<AccessPolicy>(p)};
    CHECK(who.allows("create", "Drive", Operation::call));
    Principal nobody{"x", {"driver"}, "password", nullptr};
    CHECK_FALSE(nobody.allows("create", "Drive", Operation::call));
}

TEST_CASE("gateway auth: lock is a right of its own, its members name objects") {
    AccessPolicy p;
    p.add_role("operator", {AccessRule{{"*"}, {"*"}, true, true, true}});  // read, write, call: no lock
    p.add_role("locker", {AccessRule{{"arm"}, {"*"}, false, false, false, true}});
    p.add_role("gripper", {AccessRule{{"arm"}, {"gripper", "tools[*]"}, false, false, false, true}});
    CHECK_FALSE(p.allows({"operator"}, "arm", "", Operation::lock));
    CHECK(p.allows({"locker"}, "arm", "", Operation::lock));           // the root object
    CHECK(p.allows({"locker"}, "arm", "gripper", Operation::lock));    // any object below it
    CHECK_FALSE(p.allows({"locker"}, "camera", "", Operation::lock));
    CHECK_FALSE(p.allows({"locker"}, "arm", "pos", Operation::read));  // lock allows no member operation
    CHECK_FALSE(p.allows({"gripper"}, "arm", "", Operation::lock));
    CHECK(p.allows({"gripper"}, "arm", "gripper", Operation::lock));
    CHECK(p.allows({"gripper"}, "arm", "tools[2]", Operation::lock));
    CHECK_FALSE(p.allows({}, "arm", "", Operation::lock));
    CHECK(operation_name(Operation::lock) == "lock");
    CHECK(refused_target("", Operation::lock) == "the root object");
    CHECK(refused_target("tools[2]", Operation::lock) == "object tools[2]");
    CHECK(refused_target("Drive", Operation::call) == "Drive");
}

TEST_CASE("gateway auth: adding devices takes read, write and call on every device and member") {
    auto p = std::make_shared<AccessPolicy>();
    p->add_role("operator", {AccessRule{{"*"}, {"*"}, true, true, true}});  // the config's "left out"
    p->add_role("split", {AccessRule{{"*"}, {"*"}, true, true, false}, AccessRule{{"*"}, {"*"}, false, false, true}});
    p->add_role("viewer", {AccessRule{{"*"}, {"*"}, true, false, false}});
    p->add_role("create_only", {AccessRule{{"create"}, {"*"}, true, true, true}});
    p->add_role("most_members", {AccessRule{{"*"}, {"Drive*"}, true, true, true}});
    CHECK(Principal{"a", {"operator"}, "password", p}.may_add_devices());
    CHECK(Principal{"b", {"split"}, "password", p}.may_add_devices());  // rules add up
    CHECK(Principal{"c", {"viewer", "operator"}, "password", p}.may_add_devices());
    CHECK_FALSE(Principal{"d", {"viewer"}, "password", p}.may_add_devices());
    CHECK_FALSE(Principal{"e", {"create_only"}, "password", p}.may_add_devices());
    CHECK_FALSE(Principal{"f", {"most_members"}, "password", p}.may_add_devices());
    CHECK_FALSE(Principal{"g", {}, "password", p}.may_add_devices());
}

TEST_CASE("gateway auth: member keys and the operation each RR request needs") {
    CHECK(member_key("", "Drive") == "Drive");
    CHECK(member_key("Webcams[0]", "Capture") == "Webcams[0].Capture");
    CHECK(member_key_for_path("cam", "cam", "Frame") == "Frame");
    CHECK(member_key_for_path("cam", "cam.Webcams[1]", "Frame") == "Webcams[1].Frame");
    CHECK(member_key_for_path("cam", "camera.x", "Frame") == "Frame");  // not below this device: root key
    CHECK(object_key_for_path("cam", "cam") == "");
    CHECK(object_key_for_path("cam", "cam.Webcams[1]") == "Webcams[1]");
    CHECK(object_key_for_path("cam", "cam.Webcams[1].lens") == "Webcams[1].lens");
    for (const char* op : {"RequestObjectLock", "RequestClientObjectLock", "ReleaseObjectLock", "ReleaseClientObjectLock",
                           "MonitorEnter", "MonitorContinueEnter", "MonitorExit"})
        CHECK(is_lock_operation(op));
    CHECK_FALSE(is_lock_operation("AuthenticateUser"));
    CHECK_FALSE(is_lock_operation("LogoutUser"));
    using T = rr::MessageEntryType;
    CHECK(operation_for_request(T::PropertyGetReq) == Operation::read);
    CHECK(operation_for_request(T::PropertySetReq) == Operation::write);
    CHECK(operation_for_request(T::FunctionCallReq) == Operation::call);
    CHECK(operation_for_request(T::GeneratorNextReq) == Operation::call);
    CHECK(operation_for_request(T::WirePeekInValueReq) == Operation::read);
    CHECK(operation_for_request(T::WirePokeOutValueReq) == Operation::write);
    CHECK(operation_for_request(T::WirePacket) == Operation::write);
    CHECK(operation_for_request(T::MemoryRead) == Operation::read);
    CHECK(operation_for_request(T::MemoryWrite) == Operation::write);
    CHECK(operation_for_request(T::PipePacket) == Operation::write);
    CHECK(operation_for_request(T::PipeConnectReq) == Operation::read);
    CHECK_FALSE(operation_for_request(T::PipePacketRet).has_value());
    CHECK_FALSE(operation_for_request(T::PipeDisconnectReq).has_value());
}

TEST_CASE("gateway auth: failed logins lock an address out for a while") {
    using namespace std::chrono_literals;
    LoginLimiter lim(LoginLimits{3, 60s, 300s, 4});
    auto t0 = LoginLimiter::Clock::time_point{} + 1000s;
    CHECK(lim.blocked_for("10.0.0.1", t0) == 0);
    CHECK_FALSE(lim.failed("10.0.0.1", t0));
    CHECK_FALSE(lim.failed("10.0.0.1", t0 + 1s));
    CHECK(lim.blocked_for("10.0.0.1", t0 + 2s) == 0);
    CHECK(lim.failed("10.0.0.1", t0 + 2s));  // third within the window
    CHECK(lim.blocked_for("10.0.0.1", t0 + 3s) == 299);
    CHECK(lim.blocked_for("10.0.0.2", t0 + 3s) == 0);  // other addresses unaffected
    CHECK(lim.blocked_for("10.0.0.1", t0 + 303s) == 0);  // lockout over
    // Failures spread wider than the window never lock out.
    CHECK_FALSE(lim.failed("10.0.0.3", t0));
    CHECK_FALSE(lim.failed("10.0.0.3", t0 + 61s));
    CHECK_FALSE(lim.failed("10.0.0.3", t0 + 122s));
    // A success clears the count.
    CHECK_FALSE(lim.failed("10.0.0.4", t0));
    CHECK_FALSE(lim.failed("10.0.0.4", t0));
    lim.succeeded("10.0.0.4");
    CHECK_FALSE(lim.failed("10.0.0.4", t0));
    // Bounded: at most 4 addresses tracked.
    for (int i = 0; i < 20; ++i) lim.failed("192.0.2." + std::to_string(i), t0 + std::chrono::seconds(i));
    CHECK(lim.tracked() <= 4);
    CHECK(address_of("10.1.2.3:5555") == "10.1.2.3");
    CHECK(address_of("[::1]:80") == "::1");
    CHECK(address_of("::1") == "::1");
    CHECK(address_of("local") == "local");
}
