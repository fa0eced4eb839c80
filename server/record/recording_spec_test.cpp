// Recording specs from JSON (POST /api/recordings) and from YAML (`record:` entries, through
// gateway_config): defaults, every key, and clear errors for bad ones.
#include <catch2/catch.hpp>

#include "server/app/gateway_config.hpp"
#include "server/record/recording_spec.hpp"

using namespace rr;
namespace record = rr::server::record;
using nlohmann::json;

TEST_CASE("record spec: defaults and every key") {
    auto d = record::spec_from_json(json{{"device", "cam"}});
    REQUIRE(d);
    CHECK(d->json);
    CHECK(d->robotraconteur);
    CHECK(d->directory == "recordings");
    CHECK(d->max_file_bytes == 256ull << 20);
    auto s = record::spec_from_json(json{{"device", "cam"},
                                         {"members", {"frames", "pos"}},
                                         {"encoding", "robotraconteur"},
                                         {"directory", "/tmp/x"},
                                         {"prefix", "p"},
                                         {"property_period_ms", 250},
                                         {"max_file_bytes", 1000000},
                                         {"max_file_seconds", 60},
                                         {"max_total_bytes", 5000000},
                                         {"duration_s", 10},
                                         {"compression", "none"}});
    INFO((s ? std::string() : s.error().message));
    REQUIRE(s);
    CHECK(s->members == std::vector<std::string>{"frames", "pos"});
    CHECK_FALSE(s->json);
    CHECK(s->robotraconteur);
    CHECK(s->property_period == std::chrono::milliseconds(250));
    CHECK(s->max_file_duration == std::chrono::seconds(60));
    CHECK_FALSE(s->compress);
    CHECK(record::spec_json(*s)["encoding"] == json({"robotraconteur"}));
}

TEST_CASE("record spec: bad keys and values are clear errors") {
    auto unknown = record::spec_from_json(json{{"device", "cam"}, {"rate", 3}});
    REQUIRE_FALSE(unknown);
    CHECK(unknown.error().message.find("record: rate: unknown key") != std::string::npos);
    auto missing = record::spec_from_json(json{{"members", json::array()}});
    REQUIRE_FALSE(missing);
    CHECK(missing.error().message == "record: device: missing");
    auto enc = record::spec_from_json(json{{"device", "cam"}, {"encoding", "ros2"}});
    REQUIRE_FALSE(enc);
    CHECK(enc.error().message.find("record: encoding") != std::string::npos);
    auto neg = record::spec_from_json(json{{"device", "cam"}, {"max_file_bytes", -1}});
    REQUIRE_FALSE(neg);
    CHECK(neg.error().message.find("max_file_bytes") != std::string::npos);
    auto budget = record::spec_from_json(json{{"device", "cam"}, {"max_file_bytes", 100000}, {"max_total_bytes", 1000}});
    REQUIRE_FALSE(budget);
}

TEST_CASE("gateway config: record entries and replay devices") {
    auto c = server::app::parse_gateway_config(R"(
devices:
  - name: cam2
    replay: /data/cam.mcap
    speed: 2
    loop: true
record:
  - device: webcam
    members: [frames]
    encoding: [json, robotraconteur]
    max_file_bytes: 1000000
)", "test.yaml");
    REQUIRE(c);
    REQUIRE(c->replays.size() == 1);
    CHECK(c->replays[0].name == "cam2");
    CHECK(c->replays[0].file == "/data/cam.mcap");
    CHECK(c->replays[0].speed == 2.0);
    CHECK(c->replays[0].loop);
    REQUIRE(c->record.size() == 1);
    CHECK(c->record[0].device == "webcam");
    CHECK(c->record[0].members == std::vector<std::string>{"frames"});
    CHECK(c->record[0].max_file_bytes == 1000000);

    auto bad = server::app::parse_gateway_config("record:\n  - device: x\n    every: 3\n", "bad.yaml");
    REQUIRE_FALSE(bad);
    CHECK(bad.error().message.find("bad.yaml:2: record[]: record: every: unknown key") != std::string::npos);
    auto bad_replay = server::app::parse_gateway_config("devices:\n  - name: r\n    replay: f.mcap\n    speed: 0\n", "r.yaml");
    REQUIRE_FALSE(bad_replay);
    CHECK(bad_replay.error().message.find("devices.r.speed") != std::string::npos);
}

TEST_CASE("record spec: foxglove_images, on by default") {
    auto d = record::spec_from_json(json{{"device", "cam"}});
    REQUIRE(d);
    CHECK(d->foxglove_images);
    CHECK(record::spec_json(*d)["foxglove_images"] == true);
    auto off = record::spec_from_json(json{{"device", "cam"}, {"foxglove_images", false}});
    REQUIRE(off);
    CHECK_FALSE(off->foxglove_images);
    auto bad = record::spec_from_json(json{{"device", "cam"}, {"foxglove_images", "no"}});
    REQUIRE_FALSE(bad);
    CHECK(bad.error().message == "record: foxglove_images: expected true or false");
}
