// `experimental.create`: the seed paper's iRobot Create service definition (Robot Raconteur 0.8),
// modernized by us for the demo device (server/demo): stdver 0.10, `constant` lines without dots
// (`DRIVE_STRAIGHT` for the paper's `DRIVE.STRAIGHT`, which the verifier rejects), `end` instead of
// `end struct` / `end object`. The members and their types are the paper's; `[readonly]` is added to
// the sensor properties and the `packets` wire (clients only read them), which changes no member.
#pragma once

#include <cstdint>
#include <string_view>

namespace rr::robdef {

/// Definition text (LF line ends, verifies without diagnostics together with the built-in set).
std::string_view experimental_create_robdef() noexcept;

inline constexpr std::string_view kExperimentalCreateServiceName = "experimental.create";
inline constexpr std::string_view kExperimentalCreateObjectType = "experimental.create.Create";
inline constexpr std::string_view kExperimentalCreateSensorPacket = "experimental.create.SensorPacket";

/// The definition's constants (radius values of Drive): drive straight, spin in place.
inline constexpr std::int16_t kCreateDriveStraight = 32767;
inline constexpr std::int16_t kCreateSpinClockwise = -1;
inline constexpr std::int16_t kCreateSpinCounterClockwise = 1;

}  // namespace rr::robdef
