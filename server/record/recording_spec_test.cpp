// Recording specs from JSON (POST /api/recordings) and from YAML (`record:` entries, through
// gateway_config): defaults, every key, and clear errors for bad ones.
#include <catch2/catch.hpp>

#include "server/app/gateway_config.hpp"
#include "server/gateway/auth/access_policy.hpp"
#include "server/record/recording_spec.hpp"

using namespace rr;
namespace record = rr::server::record;
using nlohmann::json;

TEST_CASE("record spec: defaults and every key") {
    auto d = record::spec_from_json(json{{"device", "cam"}});
    REQUIRE(d);
    CHECK(d->encodes("json"));
    CHECK(d->encodes("robotraconteur"));
    CHECK(d->directory.empty());  // the recordings root itself
    CHECK(d->max_file_bytes == 256ull << 20);
    auto s = record::spec_from_json(json{{"device", "cam"},
                                         {"members", {"frames", "pos"}},
                                         {"encoding", "robotraconteur"},
                                         {"directory", "lab/run-1.a"},
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
    CHECK(s->directory == "lab/run-1.a");
    CHECK_FALSE(s->encodes("json"));
    CHECK(s->encodes("robotraconteur"));
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

TEST_CASE("record spec: a directory names a sub-folder of the root, a prefix a plain name (400 otherwise)") {
    auto refused = [](json body, const std::string& expected) {
        body["device"] = "create";
        auto s = record::spec_from_json(body);
        INFO(body.dump());
        REQUIRE_FALSE(s);
        CHECK(s.error().type == MessageErrorType::InvalidArgument);
        CHECK_THAT(s.error().message, Catch::Contains(expected));
    };
    // issue 52: the prefix was cut at the NUL and the file opened without O_EXCL, replacing /tmp/victim.txt
    refused(json{{"directory", "/tmp"}}, "record: directory: \"/tmp\" is an absolute path");
    refused(json{{"prefix", std::string("victim.txt\0", 11)}}, "record: prefix: \"victim.txt\\u0000\" has the character \"\\u0000\"");
    refused(json{{"directory", ".."}}, "a part starting with a dot (\"..\"");
    refused(json{{"directory", "a/../../etc"}}, "a part starting with a dot (\"..\"");
    refused(json{{"directory", "a/./b"}}, "a part starting with a dot");
    refused(json{{"directory", "a//b"}}, "an empty part");
    refused(json{{"directory", "a/"}}, "an empty part");
    refused(json{{"directory", "a\\b"}}, "the character \"\\\\\"");
    refused(json{{"directory", std::string(65, 'x')}}, "at most 64");
    refused(json{{"directory", "a/b/c/d/e/f/g/h/i"}}, "more than 8 levels");
    refused(json{{"prefix", "a/b"}}, "the character \"/\"");
    refused(json{{"prefix", ".hidden"}}, "starting with a dot");
    refused(json{{"prefix", "sp ace"}}, "the character \" \"");
    refused(json{{"prefix", std::string(65, 'p')}}, "at most 64");
    for (const char* ok : {"", "a", "lab/run1", "A-b_c.d/e.f", "x/y/z/1/2/3/4/5"}) {
        auto s = record::spec_from_json(json{{"device", "create"}, {"directory", ok}, {"prefix", "cam_1.front-left"}});
        INFO(ok);
        CHECK(s);
    }
}

TEST_CASE("record spec: queue_bytes over recordings.max_queue_bytes is refused, naming the bound") {
    record::RecordingsSettings settings;
    CHECK(settings.max_queue_bytes == 256u << 20);
    auto s = record::spec_from_json(json{{"device", "create"}, {"queue_bytes", 1000000000000ull}});
    REQUIRE(s);  // the syntax is fine: the gateway's bound is its own
    auto r = record::check_spec_bounds(*s, settings);
    REQUIRE_FALSE(r);
    CHECK_THAT(r.error().message, Catch::Contains("queue_bytes: 1000000000000 is over the gateway's limit of 268435456 (recordings.max_queue_bytes)"));
    s->queue_bytes = 256u << 20;
    CHECK(record::check_spec_bounds(*s, settings));
    // The default (64 MiB) is not refused under a smaller bound: the gateway lowers it.
    settings.max_queue_bytes = 1u << 20;
    auto d = record::spec_from_json(json{{"device", "create"}});
    REQUIRE(d);
    CHECK_FALSE(d->queue_bytes_given);
    CHECK(record::check_spec_bounds(*d, settings));
}

TEST_CASE("record spec: the default root is the state directory's recordings folder, else the working directory's") {
    CHECK(record::default_recordings_root(nullptr) == "recordings");
    CHECK(record::default_recordings_root("") == "recordings");
    CHECK(record::default_recordings_root("/var/lib/rr-gateway") == "/var/lib/rr-gateway/recordings");
    CHECK(record::default_recordings_root("/var/lib/rr-gateway/") == "/var/lib/rr-gateway/recordings");
    CHECK(record::default_recordings_root("/var/lib/a:/var/lib/b") == "/var/lib/a/recordings");
}

TEST_CASE("gateway config: recordings bounds, --recordings-root, and the record right in roles") {
    auto c = server::app::parse_gateway_config(R"(
gateway:
  auth:
    tokens: /etc/rr-gateway/tokens.txt
    roles:
      recorder:
        - devices: [create]
          allow: [read, record]
recordings:
  root: /data/rec
  max_total_bytes: 10485760
  max_active: 2
  max_queue_bytes: 1048576
  keep_ended: 5
  replay_memory_bytes: 33554432
record:
  - device: create
    directory: lab/daily
)", "rec.yaml");
    INFO((c ? std::string() : c.error().message));
    REQUIRE(c);
    CHECK(c->recordings.root == "/data/rec");
    CHECK(c->recordings.max_total_bytes == 10485760);
    CHECK(c->recordings.max_active == 2);
    CHECK(c->recordings.max_queue_bytes == 1048576);
    CHECK(c->recordings.keep_ended == 5);
    CHECK(c->recordings.replay_memory_bytes == 33554432);
    CHECK(c->record.at(0).directory == "lab/daily");
    const auto& rule = c->auth.roles.at(0).second.at(0);
    CHECK(rule.record);
    CHECK(rule.read);
    CHECK_FALSE(rule.write);

    // Defaults: the documented ones.
    auto d = server::app::parse_gateway_config("demo:\n  enabled: true\n", "d.yaml");
    REQUIRE(d);
    CHECK(d->recordings.root.empty());
    CHECK(d->recordings.max_total_bytes == 2ull << 30);
    CHECK(d->recordings.max_active == 8);
    CHECK(d->recordings.max_queue_bytes == 256u << 20);
    CHECK(d->recordings.replay_memory_bytes == 256ull << 20);

    for (auto [yaml, expect] : std::vector<std::pair<std::string, std::string>>{
             {"recordings:\n  roots: /x\n", "recordings.roots: unknown key"},
             {"recordings:\n  max_active: 0\n", "recordings.max_active: must be at least 1"},
             {"recordings:\n  max_total_bytes: 1000\n", "recordings.max_total_bytes: must be at least 1048576"},
             {"record:\n  - device: create\n    directory: /tmp\n", "record: directory: \"/tmp\" is an absolute path"},
             {"record:\n  - device: create\n    directory: ../x\n", "starting with a dot"},
             {"recordings:\n  max_queue_bytes: 65536\nrecord:\n  - device: create\n    queue_bytes: 1048576\n",
              "bad.yaml:4: record[]: record: queue_bytes: 1048576 is over the gateway's limit of 65536 (recordings.max_queue_bytes)"}}) {
        auto bad = server::app::parse_gateway_config(yaml, "bad.yaml");
        INFO(yaml);
        REQUIRE_FALSE(bad);
        CHECK_THAT(bad.error().message, Catch::Contains(expect));
    }

    // The flag sets the root.
    const char* argv[] = {"rr-gateway", "--recordings-root", "/srv/rec"};
    auto cmd = server::app::parse_command_line(3, argv);
    REQUIRE(cmd);
    server::app::GatewayConfig flagged;
    REQUIRE(server::app::apply_overrides(flagged, *cmd));
    CHECK(flagged.recordings.root == "/srv/rec");
}

TEST_CASE("access policy: record is a right of its own, not implied by write") {
    using server::gateway::auth::AccessPolicy;
    using server::gateway::auth::AccessRule;
    using server::gateway::auth::Operation;
    AccessPolicy policy;
    policy.add_role("operator", {AccessRule{{"*"}, {"*"}, true, true, true}});
    policy.add_role("recorder", {AccessRule{.devices = {"create"}, .members = {"*"}, .read = true, .record = true}});
    policy.add_role("member_only", {AccessRule{.devices = {"*"}, .members = {"packets"}, .record = true}});
    CHECK_FALSE(policy.allows({"operator"}, "create", "*", Operation::record));
    CHECK(policy.allows({"operator"}, "create", "*", Operation::write));
    CHECK(policy.allows({"recorder"}, "create", "*", Operation::record));
    CHECK_FALSE(policy.allows({"recorder"}, "webcam", "*", Operation::record));
    CHECK_FALSE(policy.allows({"recorder"}, "create", "*", Operation::write));
    // Asked on member `*`: a rule naming members does not give it.
    CHECK_FALSE(policy.allows({"member_only"}, "create", "*", Operation::record));
    CHECK(server::gateway::auth::operation_name(Operation::record) == "record");
}
