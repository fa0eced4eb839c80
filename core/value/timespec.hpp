// The wire TimeSpec (wire.md §3.2 "Time stamps"): a struct `RobotRaconteur.TimeSpec` with fields
// `seconds` (int64 scalar) and `nanoseconds` (int32 scalar, 0 ≤ ns < 1e9), counted from 1970-01-01 UTC.
// Wire values carry one as their `ts` timestamp; these helpers need no robdef.
#pragma once

#include <cstdint>
#include <string_view>

#include "base/error/rr_error.hpp"
#include "base/message/message.hpp"
#include "core/value/value.hpp"

namespace rr {

inline constexpr std::string_view kTimeSpecTypeName = "RobotRaconteur.TimeSpec";

struct TimeSpec {
    std::int64_t seconds = 0;
    std::int32_t nanoseconds = 0;  ///< 0 ≤ nanoseconds < 1'000'000'000
    friend auto operator<=>(const TimeSpec&, const TimeSpec&) = default;
};

/// 101 element "RobotRaconteur.TimeSpec" { seconds:int64[1], nanoseconds:int32[1] }, named `element_name`.
MessageElement pack_timespec(const TimeSpec& t, std::string_view element_name);

/// Reads a TimeSpec element. Errors: DataTypeMismatch (not a RobotRaconteur.TimeSpec struct, or a field of
/// the wrong type), MessageElementNotFound (missing field), DataTypeError (field not one item, or
/// nanoseconds outside [0, 1e9)), NullValue (void element).
Result<TimeSpec> unpack_timespec(const MessageElement& e);

/// The same as a Structure value.
Value timespec_to_value(const TimeSpec& t);
/// Errors as unpack_timespec.
Result<TimeSpec> timespec_from_value(const Value& v);

}  // namespace rr
