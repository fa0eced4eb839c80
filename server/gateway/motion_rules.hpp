// Which members of a device move it, and how the gateway keeps each motion bounded (docs/security.md
// "Motion safety"). Pure: no I/O, no clock; MotionGuard (motion_guard.hpp) applies the rules.
//
// Four kinds of member, on the device's root object:
//   * hold-to-run functions: one argument is the motion's own timeout; the gateway clamps it to
//     `hold_to_run_max` (the standard robot's jog_joint and jog_cartesian, argument `timeout`, seconds);
//   * motions without a timeout of their own: a function with a `wait` argument (false: it returns at
//     once and the robot keeps moving; the standard robot's jog_freespace) or a generator function
//     (execute_trajectory, home): ended by the gateway (the device's stop) when the client that started
//     them goes away;
//   * command streams: wires whose OutValue commands motion (position_command, velocity_command):
//     ended by the gateway when their sender goes silent for the bound;
//   * stops: a function (halt) or a property value (command_mode = halt) that ends motion; they reach the
//     device whatever lock another client holds, and they are what the gateway calls to end a motion.
// The standard robot's set (com.robotraconteur.robotics.robot.Robot, as root type or implemented), the
// standard tool's (com.robotraconteur.robotics.tool.Tool), servo's (com.robotraconteur.servo.Servo) and
// actuator's (com.robotraconteur.actuator.Actuator) are built in; a configuration adds members of any
// device (safety.hold_to_run, .motions, .streams, .stops).
#pragma once

#include <chrono>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "base/error/rr_error.hpp"
#include "base/message/message.hpp"
#include "core/session/service_host.hpp"

namespace rr::server::gateway {

class DeviceTypes;

inline constexpr std::string_view kStandardRobotType = "com.robotraconteur.robotics.robot.Robot";
/// The standard tool (grippers): open(), close(), setf_command() and home() start a motion that lasts
/// until halt() (its stop) or its client's end.
inline constexpr std::string_view kStandardToolType = "com.robotraconteur.robotics.tool.Tool";
/// The standard servo: command streams position_command, velocity_command and effort_command,
/// trapezoidal_move() runs until halt() (or `mode` set to halt) or its client's end.
inline constexpr std::string_view kStandardServoType = "com.robotraconteur.servo.Servo";
/// The standard actuator: the actuator_command stream, stopped by `actuator_mode` set to halt.
inline constexpr std::string_view kStandardActuatorType = "com.robotraconteur.actuator.Actuator";

/// A function one of whose arguments is the motion's own timeout.
struct HoldToRunMember {
    std::string member;
    std::string timeout_arg;  ///< the parameter's name
    double unit_s = 1.0;      ///< seconds per unit of that argument (0.001 for milliseconds)
};

/// A motion without a timeout of its own: a generator function, or a function whose `wait_arg` (a
/// bool parameter; "" = none) says whether the call returns only when the motion is done.
struct UntimedMotionMember {
    std::string member;
    std::string wait_arg;
};

/// A function without parameters that stops motion, or (with `value`) a property set to that number.
struct StopMember {
    std::string member;
    std::optional<double> value;
};

/// `safety:` for one device (the gateway-wide settings with the device's overrides applied).
struct MotionSafety {
    /// Longest timeout a hold-to-run call may ask for; also how long a command stream may stay silent,
    /// and how soon a client that stops answering is noticed while it holds a motion without a timeout.
    std::chrono::milliseconds hold_to_run_max{500};
    /// The standard robot's (or standard tool's, servo's, actuator's) members are guarded when the device
    /// is one (false: only the lists below).
    bool standard_robot = true;
    std::vector<HoldToRunMember> hold_to_run;
    std::vector<UntimedMotionMember> motions;
    std::vector<std::string> streams;
    std::vector<StopMember> stops;
};

/// The rules of one device, compiled when it connects (its root type known).
class MotionRules {
public:
    MotionRules() = default;
    /// `types` (may be null) gives the stop property's type and the standard robot's `halt` command
    /// mode value (0 without them, as the standard defines it).
    static MotionRules compile(const MotionSafety& settings, const ObjectTypeInfo& root, const DeviceTypes* types);

    /// Nothing is guarded (no standard robot, nothing configured).
    bool empty() const noexcept {
        return hold_to_run_.empty() && untimed_.empty() && streams_.empty() && stop_functions_.empty() && stop_properties_.empty();
    }
    bool standard_robot() const noexcept { return standard_robot_; }
    bool standard_tool() const noexcept { return standard_tool_; }
    /// The standard servo's or actuator's set applies (kStandardServoType, kStandardActuatorType).
    bool standard_servo() const noexcept { return standard_servo_; }
    bool standard_actuator() const noexcept { return standard_actuator_; }
    std::chrono::milliseconds bound() const noexcept { return bound_; }

    const HoldToRunMember* hold_to_run(std::string_view member) const;
    const UntimedMotionMember* untimed(std::string_view member) const;
    bool stream(std::string_view member) const;
    bool stop_function(std::string_view member) const;
    /// A PropertySetReq's `value` element stops motion.
    bool stop_property(std::string_view member, const MessageElement& value) const;
    /// Any member of the four kinds above.
    bool guards(std::string_view member) const;

    /// What the gateway sends the device to end a motion (root object at `path`): each stop function
    /// called, then each stop property set, in that order.
    std::vector<MessageEntry> stop_requests(const std::string& path) const;

private:
    struct StopProperty {
        std::string member;
        double value = 0;
        DataTypes type = DataTypes::int32_t;  ///< how the value travels (enums as int32)
    };
    bool standard_robot_ = false;
    bool standard_tool_ = false;
    bool standard_servo_ = false;
    bool standard_actuator_ = false;
    std::chrono::milliseconds bound_{500};
    std::vector<HoldToRunMember> hold_to_run_;
    std::vector<UntimedMotionMember> untimed_;
    std::vector<std::string> streams_;
    std::vector<std::string> stop_functions_;
    std::vector<StopProperty> stop_properties_;
};

/// The number in a scalar numeric or bool element (nullopt for anything else).
std::optional<double> scalar_number(const MessageElement& e);

/// Clamps the timeout argument of a hold-to-run FunctionCallReq in place to `max`: a larger, infinite
/// or NaN timeout becomes `max` (in the argument's own unit and type, integers rounded down); a smaller
/// one is kept (the device judges zero and negative ones). Returns the timeout the call now carries,
/// seconds. Errors: InvalidArgument when the argument is missing or not a numeric scalar.
Result<double> clamp_timeout(MessageEntry& call, const HoldToRunMember& rule, std::chrono::milliseconds max);

/// The `name` argument of a call as a bool (a bool or numeric scalar); nullopt when absent or another type.
std::optional<bool> bool_argument(const MessageEntry& call, std::string_view name);

}  // namespace rr::server::gateway
