// The Create device without a network: simulated time through advance(), the properties' values,
// the SensorPacket layout.
#include <catch2/catch.hpp>

#include "server/demo/create_device.hpp"

using namespace rr;
using namespace rr::server::demo;
using namespace std::chrono_literals;

namespace {

template <class T>
T get_le(const std::vector<std::uint8_t>& d, std::size_t off) {
    using U = std::make_unsigned_t<T>;
    U u = 0;
    for (std::size_t i = 0; i < sizeof(T); ++i) u = static_cast<U>(u | (static_cast<U>(d.at(off + i)) << (8 * i)));
    return static_cast<T>(u);
}

std::vector<std::uint8_t> packet_data(const Value& packet) {
    const auto* s = packet.get_if<Structure>();
    REQUIRE(s);
    CHECK(s->type_name == "experimental.create.SensorPacket");
    REQUIRE(s->find("ID"));
    CHECK(*s->find("ID")->as<std::uint8_t>() == kSensorPacketId);
    const auto* data = s->find("Data");
    REQUIRE(data);
    const auto* a = data->get_if<NumericArray>();
    REQUIRE(a);
    REQUIRE(a->type() == DataTypes::uint8_t);
    return {a->view<std::uint8_t>().begin(), a->view<std::uint8_t>().end()};
}

}  // namespace

TEST_CASE("create device: advance() runs the simulation in 20 ms steps, remainders carried") {
    auto dev = CreateDevice::create();
    REQUIRE(dev);
    auto& d = **dev;
    REQUIRE(d.drive(250, 32767));
    for (int i = 0; i < 300; ++i) d.advance(10ms);  // 3 s in half steps
    CHECK(d.state().time_s == Approx(3.0));
    CHECK(d.state().distance_mm == Approx(750.0).margin(1e-6));
    d.advance(15ms);  // less than a step: nothing yet
    CHECK(d.state().time_s == Approx(3.0));
    d.advance(5ms);
    CHECK(d.state().time_s == Approx(3.02));

    auto refused = d.drive(600, 32767);
    REQUIRE_FALSE(refused);
    CHECK(refused.error().type == MessageErrorType::InvalidArgument);

    // Into the east wall: stops there, bumpers set.
    for (int i = 0; i < 3; ++i) d.advance(1s);  // 755 mm + 750 mm > 1335 mm
    CHECK(d.state().bumps == 1);
    CHECK(d.state().velocity == 0);
    CHECK(d.state().bumpers == 3);
    CHECK(d.state().distance_mm == Approx(1335.0).margin(1e-6));
    CHECK_FALSE(d.streaming());
    CHECK(d.play_stats().calls == 0);  // nobody streams: no callback
    CHECK(d.packet_sequence() == 0);   // nor packets
}

TEST_CASE("create device: SensorPacket Data layout") {
    CreateState s;
    s.x_mm = -1234.4;
    s.y_mm = 567.6;
    s.heading_rad = -3.14159265358979323846 / 2;  // 270°
    s.distance_mm = -42.5;
    s.angle_deg = 725.2;
    s.velocity = -300;
    s.radius = -1;
    s.bumpers = 2;
    s.bumps = 70000;
    s.time_s = 12.3456;
    const auto raw = encode_sensor_data(s, 513, {60, 32, 62, 32}, true);
    const std::vector<std::uint8_t> d(raw.begin(), raw.end());
    REQUIRE(d.size() == kSensorDataSize);
    CHECK(d[0] == 1);
    CHECK(d[1] == 2);
    CHECK(get_le<std::uint16_t>(d, 2) == 513);
    CHECK(get_le<std::int32_t>(d, 4) == -43);  // rounded half away from zero
    CHECK(get_le<std::int32_t>(d, 8) == 725);
    CHECK(get_le<std::int32_t>(d, 12) == -1234);
    CHECK(get_le<std::int32_t>(d, 16) == 568);
    CHECK(get_le<std::int32_t>(d, 20) == 27000);
    CHECK(get_le<std::int16_t>(d, 24) == -300);
    CHECK(get_le<std::int16_t>(d, 26) == -1);
    CHECK(get_le<std::uint32_t>(d, 28) == 12345);
    CHECK(get_le<std::uint16_t>(d, 32) == 70000 - 65536);
    CHECK(d[34] == 4);
    CHECK(d[35] == 60);
    const auto none = encode_sensor_data(s, 1, {}, false);
    CHECK(none[34] == 0);
    CHECK(none[35] == 0);
}

TEST_CASE("create device: the packets wire holds a SensorPacket from the start") {
    auto dev = CreateDevice::create();
    REQUIRE(dev);
    auto& d = **dev;
    d.place(100, -200, 90);
    const auto d0 = packet_data(d.sensor_packet());
    CHECK(get_le<std::int32_t>(d0, 12) == 100);
    CHECK(get_le<std::int32_t>(d0, 16) == -200);
    CHECK(get_le<std::int32_t>(d0, 20) == 9000);
    auto wire = d.object()->wire("packets").value();
    auto initial = wire->out_value();
    REQUIRE(initial);
    const auto w0 = packet_data(initial->value);
    CHECK(get_le<std::uint16_t>(w0, 2) == 0);
    CHECK(get_le<std::int32_t>(w0, 12) == 0);  // set before place()
}
