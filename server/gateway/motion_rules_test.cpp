// MotionRules without a device: the standard robot's members found by its root type (or an implemented
// type), the standard tool's, servo's and actuator's, configured members of any device, the timeout
// clamp in each numeric type, stops recognised by their value (a halt mode from the device's own enum),
// and the stop requests the gateway sends.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

#include "core/session/elements.hpp"
#include "server/gateway/device_types.hpp"
#include "server/gateway/motion_rules.hpp"

using namespace rr;
using namespace rr::server::gateway;

namespace {

MessageEntry call(std::string member, std::vector<MessageElement> args) {
    MessageEntry e;
    e.entry_type = MessageEntryType::FunctionCallReq;
    e.service_path = "arm";
    e.member_name = std::move(member);
    e.elements = std::move(args);
    return e;
}

const ObjectTypeInfo kRobot{std::string(kStandardRobotType), {}};

}  // namespace

TEST_CASE("motion rules: the standard robot's members, by root type or an implemented one", "[motion]") {
    MotionSafety s;
    auto r = MotionRules::compile(s, kRobot, nullptr);
    CHECK(r.standard_robot());
    REQUIRE(r.hold_to_run("jog_joint"));
    CHECK(r.hold_to_run("jog_joint")->timeout_arg == "timeout");
    REQUIRE(r.hold_to_run("jog_cartesian"));
    REQUIRE(r.untimed("jog_freespace"));
    CHECK(r.untimed("jog_freespace")->wait_arg == "wait");
    REQUIRE(r.untimed("execute_trajectory"));
    CHECK(r.untimed("execute_trajectory")->wait_arg.empty());
    CHECK(r.untimed("home"));
    CHECK(r.stream("position_command"));
    CHECK(r.stream("velocity_command"));
    CHECK(r.stop_function("halt"));
    CHECK_FALSE(r.guards("robot_state"));
    CHECK_FALSE(r.guards("enable"));

    auto implemented = MotionRules::compile(s, ObjectTypeInfo{"vendor.arm.Arm", {std::string(kStandardRobotType)}}, nullptr);
    CHECK(implemented.hold_to_run("jog_joint"));

    auto other = MotionRules::compile(s, ObjectTypeInfo{"experimental.create.Create", {}}, nullptr);
    CHECK(other.empty());

    s.standard_robot = false;
    CHECK(MotionRules::compile(s, kRobot, nullptr).empty());
}

TEST_CASE("motion rules: the standard tool's open, close, setf_command and home run until halt", "[motion]") {
    MotionSafety s;
    auto r = MotionRules::compile(s, ObjectTypeInfo{std::string(kStandardToolType), {}}, nullptr);
    CHECK(r.standard_tool());
    CHECK_FALSE(r.standard_robot());
    for (const char* m : {"open", "close", "setf_command", "home"}) {
        INFO(m);
        REQUIRE(r.untimed(m));
        CHECK(r.untimed(m)->wait_arg.empty());
    }
    CHECK(r.stop_function("halt"));
    CHECK_FALSE(r.hold_to_run("jog_joint"));
    CHECK_FALSE(r.guards("enable"));
    CHECK_FALSE(r.guards("tool_state"));
    // halt() is all the gateway sends to stop a tool (a tool has no command_mode)
    auto stops = r.stop_requests("gripper");
    REQUIRE(stops.size() == 1);
    CHECK(stops[0].member_name == "halt");
    CHECK(stops[0].entry_type == MessageEntryType::FunctionCallReq);

    CHECK(MotionRules::compile(s, ObjectTypeInfo{"vendor.grip.Gripper", {std::string(kStandardToolType)}}, nullptr).standard_tool());
    s.standard_robot = false;  // the one switch turns both standard sets off
    CHECK(MotionRules::compile(s, ObjectTypeInfo{std::string(kStandardToolType), {}}, nullptr).empty());
}

TEST_CASE("motion rules: configured members of any device", "[motion]") {
    MotionSafety s;
    s.hold_to_run.push_back({"Drive", "duration_ms", 0.001});
    s.motions.push_back({"MoveTo", "wait"});
    s.streams.push_back({"joint_command"});
    s.stops.push_back({"StopAll", std::nullopt});
    s.stops.push_back({"mode", 3.0});
    auto r = MotionRules::compile(s, ObjectTypeInfo{"experimental.create.Create", {}}, nullptr);
    CHECK_FALSE(r.standard_robot());
    CHECK(r.hold_to_run("Drive"));
    CHECK(r.untimed("MoveTo"));
    CHECK(r.stream("joint_command"));
    CHECK(r.stop_function("StopAll"));
    CHECK(r.stop_property("mode", make_scalar_element<std::int32_t>("value", 3)));
    CHECK_FALSE(r.stop_property("mode", make_scalar_element<std::int32_t>("value", 2)));
    CHECK_FALSE(r.stop_property("other", make_scalar_element<std::int32_t>("value", 3)));
    CHECK_FALSE(r.hold_to_run("jog_joint"));
}

TEST_CASE("motion rules: command_mode = halt is a stop, another mode is not", "[motion]") {
    auto r = MotionRules::compile(MotionSafety{}, kRobot, nullptr);
    CHECK(r.stop_property("command_mode", make_scalar_element<std::int32_t>("value", 0)));
    CHECK_FALSE(r.stop_property("command_mode", make_scalar_element<std::int32_t>("value", 1)));
    CHECK_FALSE(r.stop_property("command_mode", make_string_element("value", "halt")));
    auto stops = r.stop_requests("arm");
    REQUIRE(stops.size() == 2);
    CHECK(stops[0].entry_type == MessageEntryType::FunctionCallReq);
    CHECK(stops[0].member_name == "halt");
    CHECK(stops[0].service_path == "arm");
    CHECK(stops[0].elements.empty());
    CHECK(stops[1].entry_type == MessageEntryType::PropertySetReq);
    CHECK(stops[1].member_name == "command_mode");
    std::int32_t mode = -1;
    REQUIRE(stops[1].find("value"));
    CHECK(read_scalar(*stops[1].find("value"), mode));
    CHECK(mode == 0);
}

TEST_CASE("motion rules: the standard servo's command streams, trapezoidal_move, halt() and mode = halt", "[motion]") {
    MotionSafety s;
    auto r = MotionRules::compile(s, ObjectTypeInfo{std::string(kStandardServoType), {}}, nullptr);
    CHECK(r.standard_servo());
    CHECK_FALSE(r.standard_robot());
    CHECK_FALSE(r.standard_tool());
    for (const char* w : {"position_command", "velocity_command", "effort_command"}) {
        INFO(w);
        CHECK(r.stream(w));
    }
    REQUIRE(r.untimed("trapezoidal_move"));
    CHECK(r.untimed("trapezoidal_move")->wait_arg.empty());
    CHECK(r.stop_function("halt"));
    CHECK(r.stop_property("mode", make_scalar_element<std::int32_t>("value", 0)));
    CHECK_FALSE(r.stop_property("mode", make_scalar_element<std::int32_t>("value", 2)));  // velocity_command
    for (const char* m : {"servo_state", "position", "servo_info", "setf_param", "setf_signal", "isoch_downsample"}) {
        INFO(m);
        CHECK_FALSE(r.guards(m));
    }
    auto stops = r.stop_requests("servo");
    REQUIRE(stops.size() == 2);
    CHECK(stops[0].member_name == "halt");
    CHECK(stops[1].entry_type == MessageEntryType::PropertySetReq);
    CHECK(stops[1].member_name == "mode");

    CHECK(MotionRules::compile(s, ObjectTypeInfo{"vendor.axis.Axis", {std::string(kStandardServoType)}}, nullptr).standard_servo());
    s.standard_robot = false;
    CHECK(MotionRules::compile(s, ObjectTypeInfo{std::string(kStandardServoType), {}}, nullptr).empty());
}

TEST_CASE("motion rules: the standard actuator's command stream, stopped by actuator_mode = halt", "[motion]") {
    MotionSafety s;
    auto r = MotionRules::compile(s, ObjectTypeInfo{std::string(kStandardActuatorType), {}}, nullptr);
    CHECK(r.standard_actuator());
    CHECK_FALSE(r.standard_servo());
    CHECK(r.stream("actuator_command"));
    CHECK_FALSE(r.stop_function("halt"));  // the standard actuator has none
    CHECK(r.stop_property("actuator_mode", make_scalar_element<std::int32_t>("value", 0)));
    CHECK_FALSE(r.stop_property("actuator_mode", make_scalar_element<std::int32_t>("value", 2)));  // normal
    CHECK_FALSE(r.guards("actuator_state"));
    CHECK_FALSE(r.guards("setf_param"));
    auto stops = r.stop_requests("conveyor");
    REQUIRE(stops.size() == 1);
    CHECK(stops[0].entry_type == MessageEntryType::PropertySetReq);
    CHECK(stops[0].member_name == "actuator_mode");
    std::int32_t mode = -1;
    REQUIRE(stops[0].find("value"));
    CHECK(read_scalar(*stops[0].find("value"), mode));
    CHECK(mode == 0);
    s.standard_robot = false;
    CHECK(MotionRules::compile(s, ObjectTypeInfo{std::string(kStandardActuatorType), {}}, nullptr).empty());
}

TEST_CASE("motion rules: the servo's halt mode is read from the device's own ServoMode", "[motion]") {
    // a vendor release numbering its modes differently: the stop the gateway sends and recognises follows it
    auto types = DeviceTypes::parse({R"(service com.robotraconteur.servo

enum ServoMode
    error = -2,
    disabled = -1,
    velocity_command = 0,
    halt = 7
end

object Servo
    property ServoMode mode [nolockread]
    function void halt()
end
)"});
    REQUIRE(types);
    auto r = MotionRules::compile(MotionSafety{}, ObjectTypeInfo{std::string(kStandardServoType), {}}, types->get());
    CHECK(r.stop_property("mode", make_scalar_element<std::int32_t>("value", 7)));
    CHECK_FALSE(r.stop_property("mode", make_scalar_element<std::int32_t>("value", 0)));
    auto stops = r.stop_requests("servo");
    REQUIRE(stops.size() == 2);
    std::int32_t mode = -1;
    REQUIRE(stops[1].find("value"));
    CHECK(read_scalar(*stops[1].find("value"), mode));
    CHECK(mode == 7);
}

TEST_CASE("motion rules: a hold-to-run timeout is clamped in its own type and unit", "[motion]") {
    const HoldToRunMember jog{"jog_joint", "timeout", 1.0};
    const std::chrono::milliseconds max{500};

    auto c = call("jog_joint", {make_array_element<double>("joint_velocity", std::vector<double>{0.1, 0, 0}),
                                make_scalar_element<double>("timeout", 60.0), make_scalar_element<bool>("wait", false)});
    auto s = clamp_timeout(c, jog, max);
    REQUIRE(s);
    CHECK(*s == Approx(0.5));
    double t = 0;
    REQUIRE(read_scalar(*c.find("timeout"), t));
    CHECK(t == Approx(0.5));
    CHECK(c.find("joint_velocity")->data.size() == 3 * sizeof(double));  // the other arguments untouched

    // A shorter timeout stays as it is (the dashboard's 0.15 s).
    auto short_call = call("jog_joint", {make_scalar_element<double>("timeout", 0.15)});
    REQUIRE(clamp_timeout(short_call, jog, max));
    REQUIRE(read_scalar(*short_call.find("timeout"), t));
    CHECK(t == 0.15);

    // Infinite and NaN become the bound; negative and zero ones are the device's to refuse.
    for (double bad : {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::quiet_NaN()}) {
        auto b = call("jog_joint", {make_scalar_element<double>("timeout", bad)});
        REQUIRE(clamp_timeout(b, jog, max));
        REQUIRE(read_scalar(*b.find("timeout"), t));
        CHECK(t == Approx(0.5));
    }
    auto neg = call("jog_joint", {make_scalar_element<double>("timeout", -1.0)});
    REQUIRE(clamp_timeout(neg, jog, max));
    REQUIRE(read_scalar(*neg.find("timeout"), t));
    CHECK(t == -1.0);

    // A configured member whose timeout is an integer of milliseconds.
    const HoldToRunMember drive{"Drive", "duration_ms", 0.001};
    auto d = call("Drive", {make_scalar_element<std::uint32_t>("duration_ms", 60000)});
    auto ds = clamp_timeout(d, drive, max);
    REQUIRE(ds);
    CHECK(*ds == Approx(0.5));
    std::uint32_t ms = 0;
    REQUIRE(read_scalar(*d.find("duration_ms"), ms));
    CHECK(ms == 500);
    auto f = call("Drive", {make_scalar_element<float>("duration_ms", 1e9f)});
    REQUIRE(clamp_timeout(f, drive, max));
    float fms = 0;
    REQUIRE(read_scalar(*f.find("duration_ms"), fms));
    CHECK(fms == Approx(500.0f));
}

TEST_CASE("motion rules: a hold-to-run call without a numeric timeout is refused", "[motion]") {
    const HoldToRunMember jog{"jog_joint", "timeout", 1.0};
    auto missing = call("jog_joint", {make_scalar_element<bool>("wait", false)});
    auto r = clamp_timeout(missing, jog, std::chrono::milliseconds(500));
    REQUIRE_FALSE(r);
    CHECK(r.error().type == MessageErrorType::InvalidArgument);
    CHECK(r.error().message.find("timeout") != std::string::npos);
    auto text = call("jog_joint", {make_string_element("timeout", "60")});
    CHECK_FALSE(clamp_timeout(text, jog, std::chrono::milliseconds(500)));
    auto array = call("jog_joint", {make_array_element<double>("timeout", std::vector<double>{60, 60})});
    CHECK_FALSE(clamp_timeout(array, jog, std::chrono::milliseconds(500)));
}

TEST_CASE("motion rules: the wait argument", "[motion]") {
    CHECK(bool_argument(call("jog_freespace", {make_scalar_element<bool>("wait", true)}), "wait") == true);
    CHECK(bool_argument(call("jog_freespace", {make_scalar_element<bool>("wait", false)}), "wait") == false);
    CHECK(bool_argument(call("jog_freespace", {make_scalar_element<std::uint8_t>("wait", 1)}), "wait") == true);
    CHECK_FALSE(bool_argument(call("jog_freespace", {}), "wait").has_value());
    CHECK_FALSE(bool_argument(call("jog_freespace", {make_string_element("wait", "yes")}), "wait").has_value());
}
