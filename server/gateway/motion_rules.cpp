#include "server/gateway/motion_rules.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "core/session/elements.hpp"
#include "server/gateway/device_types.hpp"

namespace rr::server::gateway {
namespace {

template <class T, class Pred>
const T* find_by(const std::vector<T>& items, Pred pred) {
    auto it = std::find_if(items.begin(), items.end(), pred);
    return it == items.end() ? nullptr : &*it;
}

const MessageElement* argument(const MessageEntry& call, std::string_view name) {
    for (const auto& e : call.elements)
        if (!e.number && e.name == name) return &e;
    return nullptr;
}

MessageElement* argument(MessageEntry& call, std::string_view name) {
    for (auto& e : call.elements)
        if (!e.number && e.name == name) return &e;
    return nullptr;
}

template <class T>
std::optional<double> read_as_double(const MessageElement& e) {
    T v;
    if (!read_scalar(e, v)) return std::nullopt;
    return static_cast<double>(v);
}

// An element of `type` named `name` holding `v` (integers rounded down, clamped to the type's range).
template <class T>
MessageElement number_element(std::string name, double v) {
    if constexpr (std::is_integral_v<T>) {
        const double lo = static_cast<double>(std::numeric_limits<T>::lowest());
        const double hi = static_cast<double>(std::numeric_limits<T>::max());
        v = std::floor(std::clamp(v, lo, hi));
    }
    return make_scalar_element<T>(std::move(name), static_cast<T>(v));
}

std::optional<MessageElement> make_number(DataTypes type, std::string name, double v) {
    switch (type) {
        case DataTypes::double_t: return number_element<double>(std::move(name), v);
        case DataTypes::single_t: return number_element<float>(std::move(name), v);
        case DataTypes::int8_t: return number_element<std::int8_t>(std::move(name), v);
        case DataTypes::uint8_t: return number_element<std::uint8_t>(std::move(name), v);
        case DataTypes::int16_t: return number_element<std::int16_t>(std::move(name), v);
        case DataTypes::uint16_t: return number_element<std::uint16_t>(std::move(name), v);
        case DataTypes::int32_t: return number_element<std::int32_t>(std::move(name), v);
        case DataTypes::uint32_t: return number_element<std::uint32_t>(std::move(name), v);
        case DataTypes::int64_t: return number_element<std::int64_t>(std::move(name), v);
        case DataTypes::uint64_t: return number_element<std::uint64_t>(std::move(name), v);
        case DataTypes::bool_t: return make_scalar_element<bool>(std::move(name), v != 0);
        default: return std::nullopt;
    }
}

// The value named `halt` of the enum type of property `property` of standard object `object_type`, in the
// device's own definition (0 without it, as the standard defines RobotCommandMode, ServoMode and
// ActuatorMode).
double standard_halt_value(const DeviceTypes* types, std::string_view object_type, std::string_view property) {
    if (!types) return 0;
    auto obj = types->find_object(object_type);
    if (!obj) return 0;
    const auto* m = obj->entry->find_member(property);
    if (!m) return 0;
    auto ref = types->set().find(m->type.type_name, obj->service->name);
    if (!ref.enumeration) return 0;
    for (const auto& v : ref.enumeration->values)
        if (v.name == "halt") return v.value;
    return 0;
}

// How a property's value travels: its primitive type, an enum as int32; nullopt for anything else.
std::optional<DataTypes> property_wire_type(const DeviceTypes* types, const ObjectTypeInfo& root, std::string_view member) {
    if (!types) return std::nullopt;
    auto obj = types->find_object(root.object_type);
    if (!obj) return std::nullopt;
    const auto* m = obj->entry->find_member(member);
    if (!m || m->kind != robdef::MemberKind::property || m->type.array != robdef::ArrayKind::none ||
        m->type.container != robdef::ContainerKind::none)
        return std::nullopt;
    if (m->type.base == DataTypes::namedtype_t || m->type.base == DataTypes::enum_t) {
        auto ref = types->set().find(m->type.type_name, obj->service->name);
        if (ref.enumeration) return DataTypes::int32_t;
        return std::nullopt;
    }
    if (make_number(m->type.base, "", 0)) return m->type.base;
    return std::nullopt;
}

}  // namespace

std::optional<double> scalar_number(const MessageElement& e) {
    switch (e.type) {
        case DataTypes::double_t: return read_as_double<double>(e);
        case DataTypes::single_t: return read_as_double<float>(e);
        case DataTypes::int8_t: return read_as_double<std::int8_t>(e);
        case DataTypes::uint8_t: return read_as_double<std::uint8_t>(e);
        case DataTypes::int16_t: return read_as_double<std::int16_t>(e);
        case DataTypes::uint16_t: return read_as_double<std::uint16_t>(e);
        case DataTypes::int32_t: return read_as_double<std::int32_t>(e);
        case DataTypes::uint32_t: return read_as_double<std::uint32_t>(e);
        case DataTypes::int64_t: return read_as_double<std::int64_t>(e);
        case DataTypes::uint64_t: return read_as_double<std::uint64_t>(e);
        case DataTypes::bool_t: {
            if (e.data.size() != 1) return std::nullopt;
            return e.data.data()[0] != std::byte{0} ? 1.0 : 0.0;
        }
        default: return std::nullopt;
    }
}

MotionRules MotionRules::compile(const MotionSafety& settings, const ObjectTypeInfo& root, const DeviceTypes* types) {
    MotionRules r;
    r.bound_ = settings.hold_to_run_max;
    auto is = [&](std::string_view type) {
        return root.object_type == type || std::find(root.implements.begin(), root.implements.end(), type) != root.implements.end();
    };
    r.standard_robot_ = is(kStandardRobotType) && settings.standard_robot;
    r.standard_tool_ = !r.standard_robot_ && is(kStandardToolType) && settings.standard_robot;
    if (r.standard_robot_) {
        r.hold_to_run_ = {{"jog_joint", "timeout", 1.0}, {"jog_cartesian", "timeout", 1.0}};
        r.untimed_ = {{"jog_freespace", "wait"}, {"execute_trajectory", ""}, {"home", ""}};
        r.streams_ = {"position_command", "velocity_command"};
        r.stop_functions_ = {"halt"};
        r.stop_properties_.push_back(StopProperty{"command_mode", standard_halt_value(types, kStandardRobotType, "command_mode"), DataTypes::int32_t});
    }
    if (r.standard_tool_) {
        // each call starts a motion and returns: it lasts until halt() or its client's end
        r.untimed_ = {{"open", ""}, {"close", ""}, {"setf_command", ""}, {"home", ""}};
        r.stop_functions_ = {"halt"};
    }
    const bool other_standard = r.standard_robot_ || r.standard_tool_;
    r.standard_servo_ = !other_standard && is(kStandardServoType) && settings.standard_robot;
    r.standard_actuator_ = !other_standard && !r.standard_servo_ && is(kStandardActuatorType) && settings.standard_robot;
    if (r.standard_servo_) {
        // commands stream on the three command wires; trapezoidal_move() returns while the servo moves
        r.untimed_ = {{"trapezoidal_move", ""}};
        r.streams_ = {"position_command", "velocity_command", "effort_command"};
        r.stop_functions_ = {"halt"};
        r.stop_properties_.push_back(StopProperty{"mode", standard_halt_value(types, kStandardServoType, "mode"), DataTypes::int32_t});
    }
    if (r.standard_actuator_) {
        // an actuator has no stop function: its mode set to halt stops it
        r.streams_ = {"actuator_command"};
        r.stop_properties_.push_back(
            StopProperty{"actuator_mode", standard_halt_value(types, kStandardActuatorType, "actuator_mode"), DataTypes::int32_t});
    }
    for (const auto& h : settings.hold_to_run) r.hold_to_run_.push_back(h);
    for (const auto& m : settings.motions) r.untimed_.push_back(m);
    for (const auto& s : settings.streams) r.streams_.push_back(s);
    for (const auto& s : settings.stops) {
        if (!s.value) {
            r.stop_functions_.push_back(s.member);
            continue;
        }
        // A property whose type is unknown (no definitions yet) is set as the configuration's number
        // would travel as a double; the device then judges it.
        auto type = property_wire_type(types, root, s.member);
        r.stop_properties_.push_back(StopProperty{s.member, *s.value, type.value_or(DataTypes::double_t)});
    }
    return r;
}

const HoldToRunMember* MotionRules::hold_to_run(std::string_view member) const {
    return find_by(hold_to_run_, [&](const HoldToRunMember& h) { return h.member == member; });
}

const UntimedMotionMember* MotionRules::untimed(std::string_view member) const {
    return find_by(untimed_, [&](const UntimedMotionMember& m) { return m.member == member; });
}

bool MotionRules::stream(std::string_view member) const {
    return std::find(streams_.begin(), streams_.end(), member) != streams_.end();
}

bool MotionRules::stop_function(std::string_view member) const {
    return std::find(stop_functions_.begin(), stop_functions_.end(), member) != stop_functions_.end();
}

bool MotionRules::stop_property(std::string_view member, const MessageElement& value) const {
    auto v = scalar_number(value);
    if (!v) return false;
    return find_by(stop_properties_, [&](const StopProperty& p) { return p.member == member && p.value == *v; }) != nullptr;
}

bool MotionRules::guards(std::string_view member) const {
    return hold_to_run(member) || untimed(member) || stream(member) || stop_function(member) ||
           find_by(stop_properties_, [&](const StopProperty& p) { return p.member == member; });
}

std::vector<MessageEntry> MotionRules::stop_requests(const std::string& path) const {
    std::vector<MessageEntry> out;
    for (const auto& f : stop_functions_) {
        MessageEntry e;
        e.entry_type = MessageEntryType::FunctionCallReq;
        e.service_path = path;
        e.member_name = f;
        out.push_back(std::move(e));
    }
    for (const auto& p : stop_properties_) {
        auto value = make_number(p.type, "value", p.value);
        if (!value) continue;
        MessageEntry e;
        e.entry_type = MessageEntryType::PropertySetReq;
        e.service_path = path;
        e.member_name = p.member;
        e.elements.push_back(std::move(*value));
        out.push_back(std::move(e));
    }
    return out;
}

Result<double> clamp_timeout(MessageEntry& call, const HoldToRunMember& rule, std::chrono::milliseconds max) {
    MessageElement* arg = argument(call, rule.timeout_arg);
    auto value = arg ? scalar_number(*arg) : std::nullopt;
    if (!value || arg->type == DataTypes::bool_t)
        return fail(MessageErrorType::InvalidArgument, "function \"" + rule.member + "\": its timeout argument \"" +
                                                           rule.timeout_arg + "\" is missing or not a number");
    const double max_s = std::chrono::duration<double>(max).count();
    const double unit = rule.unit_s > 0 ? rule.unit_s : 1.0;
    const double seconds = *value * unit;
    if (std::isfinite(seconds) && seconds <= max_s) return seconds;
    auto clamped = make_number(arg->type, arg->name, max_s / unit);
    if (!clamped) return fail(MessageErrorType::InvalidArgument, "timeout argument of an unsupported type");
    *arg = std::move(*clamped);
    return scalar_number(*arg).value_or(0) * unit;
}

std::optional<bool> bool_argument(const MessageEntry& call, std::string_view name) {
    const MessageElement* arg = argument(call, name);
    if (!arg) return std::nullopt;
    auto v = scalar_number(*arg);
    if (!v) return std::nullopt;
    return *v != 0;
}

}  // namespace rr::server::gateway
