// The simulated Create's physics (create_sim.hpp) on simulated time: straight, backwards, spin, arc,
// walls (stop, bump count, bumper bits), argument checks.
#include <catch2/catch.hpp>

#include <cmath>

#include "server/demo/create_sim.hpp"

using namespace rr;
using namespace rr::server::demo;

namespace {

constexpr double kDt = 0.02;  // 50 Hz, as the device runs it

/// Steps for `seconds`; returns how many steps reported a bump.
int run(CreateSimulation& sim, double seconds) {
    int bumps = 0;
    const int n = static_cast<int>(std::lround(seconds / kDt));
    for (int i = 0; i < n; ++i) bumps += sim.step(kDt) ? 1 : 0;
    return bumps;
}

constexpr double kPi = 3.14159265358979323846;

}  // namespace

TEST_CASE("create sim: driving straight integrates distance = v * t along the heading") {
    CreateSimulation sim;
    REQUIRE(sim.drive(200, 32767));
    CHECK(run(sim, 5.0) == 0);
    const auto& s = sim.state();
    CHECK(s.distance_mm == Approx(1000.0).margin(0.01));
    CHECK(s.x_mm == Approx(1000.0).margin(0.01));
    CHECK(s.y_mm == Approx(0.0).margin(1e-9));
    CHECK(s.angle_deg == Approx(0.0).margin(1e-9));
    CHECK(s.bumpers == 0);
    CHECK(s.bumps == 0);
    CHECK(s.velocity == 200);
    CHECK(s.time_s == Approx(5.0));

    SECTION("backwards subtracts; radius 0 and -32768 are straight too") {
        REQUIRE(sim.drive(-100, 0));
        run(sim, 3.0);
        CHECK(sim.state().distance_mm == Approx(700.0).margin(0.01));
        CHECK(sim.state().x_mm == Approx(700.0).margin(0.01));
        REQUIRE(sim.drive(-100, -32768));
        run(sim, 1.0);
        CHECK(sim.state().x_mm == Approx(600.0).margin(0.01));
    }
    SECTION("Drive(0, …) stops") {
        REQUIRE(sim.drive(0, 32767));
        run(sim, 2.0);
        CHECK(sim.state().distance_mm == Approx(1000.0).margin(0.01));
    }
}

TEST_CASE("create sim: spinning in place turns at v / (wheel base / 2) without moving") {
    CreateSimulation sim;
    const double half_base = sim.geometry().wheel_base_mm / 2;  // 129 mm
    REQUIRE(sim.drive(129, 1));                                 // SPIN_COUNTERCLOCKWISE: 1 rad/s
    run(sim, 2.0);
    CHECK(sim.state().angle_deg == Approx(2.0 * 180.0 / kPi * 129.0 / half_base).margin(1e-6));
    CHECK(sim.state().distance_mm == 0.0);
    CHECK(sim.state().x_mm == 0.0);
    CHECK(sim.state().y_mm == 0.0);
    CHECK(sim.state().heading_rad == Approx(2.0));

    REQUIRE(sim.drive(129, -1));  // SPIN_CLOCKWISE
    run(sim, 3.0);
    CHECK(sim.state().angle_deg == Approx(-1.0 * 180.0 / kPi).margin(1e-6));
    CHECK(sim.state().heading_rad == Approx(-1.0));

    SECTION("a full turn wraps the heading but not AngleTraveled") {
        REQUIRE(sim.drive(129, 1));
        run(sim, 2 * kPi + 1.0);  // back to heading 0 (+ rounding of the step count)
        CHECK(sim.state().angle_deg > 300.0);
        CHECK(std::abs(sim.state().heading_rad) < 0.05);
    }
}

TEST_CASE("create sim: an arc follows the circle of the given radius") {
    CreateSimulation sim;
    REQUIRE(sim.drive(200, 500));  // left turn, ω = 0.4 rad/s
    const double half_turn_s = kPi / 0.4;
    // Exact integration: one big step equals many small ones.
    CreateSimulation big;
    REQUIRE(big.drive(200, 500));
    big.step(half_turn_s);
    for (int i = 0; i < 1000; ++i) sim.step(half_turn_s / 1000);
    for (const auto* s : {&sim.state(), &big.state()}) {
        CHECK(s->x_mm == Approx(0.0).margin(1e-6));
        CHECK(s->y_mm == Approx(1000.0).margin(1e-6));
        CHECK(std::abs(s->heading_rad) == Approx(kPi));
        CHECK(s->angle_deg == Approx(180.0));
        CHECK(s->distance_mm == Approx(200 * half_turn_s));
        CHECK(s->bumps == 0);
    }
    SECTION("negative radius turns right") {
        CreateSimulation r;
        REQUIRE(r.drive(200, -500));
        r.step(1.0);
        CHECK(r.state().y_mm < 0);
        CHECK(r.state().angle_deg == Approx(-0.4 * 180.0 / kPi));
    }
}

TEST_CASE("create sim: a wall stops the robot, counts a bump and sets the bumpers") {
    CreateSimulation sim;
    const double limit = sim.geometry().room_width_mm / 2 - sim.geometry().robot_radius_mm;  // 1335 mm
    REQUIRE(sim.drive(300, 32767));
    CHECK(run(sim, 10.0) == 1);  // one hit, then it stands still
    const auto& s = sim.state();
    CHECK(s.x_mm == Approx(limit));
    CHECK(s.distance_mm == Approx(limit).margin(1e-6));
    CHECK(s.velocity == 0);
    CHECK(s.bumps == 1);
    CHECK(s.bumpers == (kBumpLeft | kBumpRight));  // head-on

    SECTION("driving into it again bumps again; backing off clears the bumpers") {
        REQUIRE(sim.drive(100, 32767));
        CHECK(sim.step(kDt));
        CHECK(sim.state().bumps == 2);
        CHECK(sim.state().x_mm == Approx(limit));
        REQUIRE(sim.drive(-100, 32767));
        CHECK_FALSE(sim.step(kDt));
        CHECK(sim.state().bumpers == 0);
        CHECK(sim.state().x_mm == Approx(limit - 2.0));
    }
    SECTION("spinning against the wall keeps the contact and does not bump") {
        REQUIRE(sim.drive(50, 1));
        CHECK(run(sim, 0.2) == 0);
        CHECK(sim.state().bumpers != 0);
    }
}

TEST_CASE("create sim: the bumper bits follow the side that touches") {
    SECTION("wall ahead-left: left bumper") {
        CreateSimulation sim;
        sim.place(0, 0, 60);  // the north wall is hit 30° to the left of the heading
        REQUIRE(sim.drive(500, 32767));
        CHECK(run(sim, 5.0) == 1);
        CHECK(sim.state().bumpers == kBumpLeft);
        CHECK(sim.state().y_mm == Approx(sim.geometry().room_depth_mm / 2 - sim.geometry().robot_radius_mm));
    }
    SECTION("wall ahead-right: right bumper") {
        CreateSimulation sim;
        sim.place(0, 0, -60);
        REQUIRE(sim.drive(500, 32767));
        CHECK(run(sim, 5.0) == 1);
        CHECK(sim.state().bumpers == kBumpRight);
    }
    SECTION("sliding along a wall after placing the robot against it is no bump") {
        CreateSimulation sim;
        const double limit = sim.geometry().room_width_mm / 2 - sim.geometry().robot_radius_mm;
        sim.place(limit, 0, 90);
        CHECK(sim.state().bumpers == kBumpRight);  // touching on its right
        REQUIRE(sim.drive(100, 32767));
        CHECK(run(sim, 2.0) == 0);
        CHECK(sim.state().y_mm == Approx(200.0).margin(1e-6));
    }
}

TEST_CASE("create sim: out-of-range drive arguments are refused and change nothing") {
    CreateSimulation sim;
    REQUIRE(sim.drive(100, 32767));
    for (auto [v, r] : {std::pair<int, int>{501, 32767}, {-501, 32767}, {100, 2001}, {100, -2001}, {100, 32766}}) {
        auto res = sim.drive(static_cast<std::int16_t>(v), static_cast<std::int16_t>(r));
        REQUIRE_FALSE(res);
        CHECK(res.error().type == MessageErrorType::InvalidArgument);
    }
    CHECK(sim.state().velocity == 100);
    CHECK(sim.state().radius == 32767);
    CHECK(sim.drive(500, 2000));
    CHECK(sim.drive(-500, -2000));
    CHECK(sim.drive(-500, -1));
}
