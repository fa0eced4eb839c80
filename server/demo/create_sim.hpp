// The physics of the simulated iRobot Create (demo device `create`, experimental.create): a round
// differential-drive robot in a rectangular room with walls. Pure model: no clock, no threads; the
// caller advances it with step(dt) (CreateDevice does so from a 50 Hz timer; tests with simulated time).
//
// Units and frame: millimetres, seconds, degrees for what the service reports (radians inside).
// The room spans x ∈ [−width/2, width/2], y ∈ [−depth/2, depth/2] (mm); the robot starts at the centre
// facing +x. Heading is counter-clockwise from +x; AngleTraveled grows counter-clockwise (as the Create
// Open Interface reports angles).
//
// Drive(velocity, radius) follows the Create Open Interface's Drive command:
//   velocity  mm/s, −500 … 500 (outside: InvalidArgument); negative drives backwards.
//   radius    mm. DRIVE_STRAIGHT (32767), −32768 and 0: straight. SPIN_CLOCKWISE (−1) and
//             SPIN_COUNTERCLOCKWISE (1): turn in place, the wheels at ±velocity. −2000 … 2000 otherwise:
//             an arc, positive radius turning left (counter-clockwise for positive velocity).
//             Other values: InvalidArgument.
// The command holds until the next Drive, or until the robot hits a wall.
//
// Integration per step (exact for constant commands):
//   straight  position += v·dt along the heading; DistanceTraveled += v·dt
//   arc       ω = v / radius; the centre moves on the circle; DistanceTraveled += v·dt; angle += ω·dt
//   spin      ω = ±v / (wheel_base / 2); no translation; DistanceTraveled unchanged (the wheels' mean
//             travel is zero); angle += ω·dt
// Walls: the robot is a disc of `robot_radius`. A step that would push it through a wall puts it back
// against the wall, stops it (velocity 0) and reports a bump: `bumps` counts up and the bumper bits
// are set from where the wall touches, relative to the heading (bit 0 right, bit 1 left, both for a
// contact within ±15° of straight ahead; a contact behind the axle sets the bit of its side too,
// a simplification: the real robot has no rear bumper). DistanceTraveled then grows by the distance
// actually moved (signed). The bits stay set while the robot touches a wall and clear once it does not.
#pragma once

#include <cstdint>

#include "base/error/rr_error.hpp"

namespace rr::server::demo {

struct CreateGeometry {
    double room_width_mm = 3000;  ///< along x
    double room_depth_mm = 2400;  ///< along y
    double robot_radius_mm = 165;
    double wheel_base_mm = 258;
};

/// Bumper bits (Create Open Interface sensor packet 7).
inline constexpr std::uint8_t kBumpRight = 0x01;
inline constexpr std::uint8_t kBumpLeft = 0x02;

inline constexpr std::int16_t kMaxVelocity = 500;  ///< mm/s
inline constexpr std::int16_t kMaxRadius = 2000;   ///< mm

/// What the robot does and has done.
struct CreateState {
    double x_mm = 0, y_mm = 0;
    double heading_rad = 0;       ///< counter-clockwise from +x, in (−π, π]
    double distance_mm = 0;       ///< signed total since start
    double angle_deg = 0;         ///< signed total since start, counter-clockwise positive
    std::int16_t velocity = 0;    ///< current command (0 after a bump)
    std::int16_t radius = 32767;  ///< current command
    std::uint8_t bumpers = 0;
    std::uint32_t bumps = 0;      ///< wall hits since start
    double time_s = 0;            ///< simulated time since start
};

class CreateSimulation {
public:
    explicit CreateSimulation(CreateGeometry geometry = {});

    /// Sets the drive command (see the header comment). Errors: InvalidArgument (velocity or radius
    /// out of range); the command is unchanged then.
    Result<void> drive(std::int16_t velocity, std::int16_t radius);
    /// Advances by `dt_s` seconds (≥ 0; large steps are fine for straight motion, arcs are exact too).
    /// Returns true when the robot hit a wall during this step.
    bool step(double dt_s);
    /// Puts the robot at a pose (tests and resets; the totals stay). The pose is clamped into the room.
    void place(double x_mm, double y_mm, double heading_deg);

    const CreateState& state() const noexcept { return state_; }
    const CreateGeometry& geometry() const noexcept { return geometry_; }

private:
    /// Moves the robot back inside the walls; returns the bumper bits of the walls it touched (0 = none).
    std::uint8_t resolve_walls(bool& penetrated);
    std::uint8_t touching() const;

    CreateGeometry geometry_;
    CreateState state_;
};

}  // namespace rr::server::demo
