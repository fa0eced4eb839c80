#include "server/demo/create_sim.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

namespace rr::server::demo {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kContactEpsilonMm = 0.5;

double wrap_angle(double a) {
    a = std::remainder(a, 2 * kPi);  // [−π, π]
    if (a <= -kPi) a += 2 * kPi;
    return a;
}

bool is_straight(std::int16_t radius) { return radius == 32767 || radius == -32768 || radius == 0; }
bool is_spin(std::int16_t radius) { return radius == 1 || radius == -1; }

/// Bumper bits for a wall touching the robot in direction `dir` (rad, world frame).
std::uint8_t bits_for_contact(double dir, double heading) {
    const double rel = wrap_angle(dir - heading);  // > 0: to the left
    constexpr double kFront = 15.0 * kPi / 180.0;
    if (std::abs(rel) <= kFront) return kBumpLeft | kBumpRight;
    return rel > 0 ? kBumpLeft : kBumpRight;
}

}  // namespace

CreateSimulation::CreateSimulation(CreateGeometry geometry) : geometry_(geometry) {}

Result<void> CreateSimulation::drive(std::int16_t velocity, std::int16_t radius) {
    if (velocity < -kMaxVelocity || velocity > kMaxVelocity)
        return fail(MessageErrorType::InvalidArgument,
                    "velocity " + std::to_string(velocity) + " mm/s is out of range (-500 to 500)");
    if (!is_straight(radius) && !is_spin(radius) && (radius < -kMaxRadius || radius > kMaxRadius))
        return fail(MessageErrorType::InvalidArgument,
                    "radius " + std::to_string(radius) +
                        " mm is out of range (-2000 to 2000, or DRIVE_STRAIGHT, SPIN_CLOCKWISE, SPIN_COUNTERCLOCKWISE)");
    state_.velocity = velocity;
    state_.radius = radius;
    return {};
}

void CreateSimulation::place(double x_mm, double y_mm, double heading_deg) {
    state_.x_mm = x_mm;
    state_.y_mm = y_mm;
    state_.heading_rad = wrap_angle(heading_deg * kPi / 180.0);
    bool penetrated = false;
    resolve_walls(penetrated);
    state_.bumpers = touching();
}

std::uint8_t CreateSimulation::touching() const {
    const double hx = geometry_.room_width_mm / 2 - geometry_.robot_radius_mm;
    const double hy = geometry_.room_depth_mm / 2 - geometry_.robot_radius_mm;
    std::uint8_t bits = 0;
    const double h = state_.heading_rad;
    if (state_.x_mm >= hx - kContactEpsilonMm) bits |= bits_for_contact(0, h);
    if (state_.x_mm <= -hx + kContactEpsilonMm) bits |= bits_for_contact(kPi, h);
    if (state_.y_mm >= hy - kContactEpsilonMm) bits |= bits_for_contact(kPi / 2, h);
    if (state_.y_mm <= -hy + kContactEpsilonMm) bits |= bits_for_contact(-kPi / 2, h);
    return bits;
}

std::uint8_t CreateSimulation::resolve_walls(bool& penetrated) {
    const double hx = std::max(0.0, geometry_.room_width_mm / 2 - geometry_.robot_radius_mm);
    const double hy = std::max(0.0, geometry_.room_depth_mm / 2 - geometry_.robot_radius_mm);
    constexpr double kTol = 1e-6;  // rounding while sliding along a wall is no hit
    penetrated = state_.x_mm > hx + kTol || state_.x_mm < -hx - kTol || state_.y_mm > hy + kTol || state_.y_mm < -hy - kTol;
    state_.x_mm = std::clamp(state_.x_mm, -hx, hx);
    state_.y_mm = std::clamp(state_.y_mm, -hy, hy);
    return touching();
}

bool CreateSimulation::step(double dt_s) {
    if (!(dt_s > 0)) return false;
    state_.time_s += dt_s;
    const double v = state_.velocity;
    const std::int16_t r = state_.radius;
    const double x0 = state_.x_mm, y0 = state_.y_mm, h0 = state_.heading_rad;
    double omega = 0;  // rad/s
    bool translating = v != 0;
    if (is_spin(r)) {
        // SPIN_COUNTERCLOCKWISE (1) with positive velocity turns counter-clockwise.
        omega = (r > 0 ? 1.0 : -1.0) * v / (geometry_.wheel_base_mm / 2);
        translating = false;
    } else if (!is_straight(r)) {
        omega = v / r;
    }
    if (translating) {
        if (omega == 0) {
            state_.x_mm += v * dt_s * std::cos(h0);
            state_.y_mm += v * dt_s * std::sin(h0);
        } else {
            const double rr = v / omega;  // signed turning radius
            state_.x_mm += rr * (std::sin(h0 + omega * dt_s) - std::sin(h0));
            state_.y_mm -= rr * (std::cos(h0 + omega * dt_s) - std::cos(h0));
        }
    }
    state_.heading_rad = wrap_angle(h0 + omega * dt_s);

    bool penetrated = false;
    const std::uint8_t bits = resolve_walls(penetrated);
    if (penetrated) {
        // Stopped at the wall: the distance is what was actually moved; the turn of this step stays.
        const double moved = std::hypot(state_.x_mm - x0, state_.y_mm - y0);
        state_.distance_mm += v >= 0 ? moved : -moved;
        state_.angle_deg += omega * dt_s * 180.0 / kPi;
        state_.velocity = 0;
        state_.radius = 32767;
        state_.bumpers = bits;
        ++state_.bumps;
        return true;
    }
    if (translating) state_.distance_mm += v * dt_s;
    state_.angle_deg += omega * dt_s * 180.0 / kPi;
    state_.bumpers = bits;
    return false;
}

}  // namespace rr::server::demo
