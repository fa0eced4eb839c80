// Recording against a real device (rr_interop_service behind a Gateway): a pipe, a wire and an event
// recorded through POST /api/recordings, read back with McapReader: channels, schemas, the pipe
// packets' values in both encodings; members below the root named by path (channels, metadata, and a
// ReplayDevice of the file serving those objects through the objrefs); rotation by size with a disk
// budget; a stop answering with the final status; bad requests.
#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>

#include "core/mcap/mcap_reader.hpp"
#include "server/gateway/json_api_test_fixture.hpp"
#include "core/names/service_path.hpp"
#include "server/gateway/mirror_service.hpp"
#include "server/gateway/session_endpoints.hpp"
#include "server/mcap/mcap_file.hpp"
#include "server/record/replay_device.hpp"
#include "test/support/eventually.hpp"

using namespace rr::server::gateway::testing;
namespace fs = std::filesystem;

namespace {

struct RecordingDir {
    fs::path path;
    RecordingDir() {
        // a folder of its own under TMPDIR (or /tmp), made atomically so parallel test runs never share one
        std::string tmpl = (fs::temp_directory_path() / "rr-recording-test-XXXXXX").string();
        REQUIRE(::mkdtemp(tmpl.data()));
        path = tmpl;
    }
    ~RecordingDir() {
        std::error_code ec;
        fs::remove_all(path, ec);
    }
};

std::map<std::string, std::vector<rr::mcap::Message>> read_recording(const std::string& file, rr::mcap::Summary* summary = nullptr) {
    auto src = rr::mcap::FileSource::open(file);
    REQUIRE(src);
    auto reader = rr::mcap::McapReader::open(**src);
    REQUIRE(reader);
    CHECK(reader->indexed());
    std::map<std::string, std::vector<rr::mcap::Message>> out;
    auto it = reader->messages();
    for (;;) {
        auto m = it.next();
        REQUIRE(m);
        if (!*m) break;
        const auto& ch = reader->summary().channels.at((*m)->channel_id);
        out[ch.topic + " " + ch.message_encoding].push_back(std::move(**m));
    }
    if (summary) *summary = reader->summary();
    return out;
}

std::string text_of(const rr::mcap::Message& m) { return std::string(reinterpret_cast<const char*>(m.data.data()), m.data.size()); }

// Waits until `n` pipe endpoints of the gateway itself (a recording's) are connected to the device:
// packets the device sends before that are not recorded.
bool gateway_pipes_open(TestGateway& gw, std::size_t n) {
    const auto endpoints = gw.gateway().devices().front()->mirror_service()->shared_endpoints();
    return rr::testing::eventually([&] { return endpoints->open_pipe_count() == n; });
}

// Waits until the recording has written at least `n` messages (GET /api/recordings/{id}; each value is
// one message per encoding: `robotraconteur` and `json`).
bool written_at_least(TestGateway& gw, std::uint64_t id, std::uint64_t n) {
    std::uint64_t last = 0;
    const bool ok = rr::testing::eventually([&] {
        auto r = http_get(gw.port(), "/api/recordings/" + std::to_string(id));
        REQUIRE(r.status == 200);
        last = r.body["messages"].get<std::uint64_t>();
        return last >= n;
    });
    INFO("messages written: " << last << ", waited for " << n);
    CHECK(ok);
    return ok;
}

}  // namespace

TEST_CASE("recording: a pipe, a wire and an event of a live device, read back") {
    RR_SKIP_WITHOUT_INTEROP_SERVICE();
    InteropProcess device;
    TestGateway gw(device.url());
    RecordingDir dir;
    auto r = http_post(gw.port(), "/api/recordings",
                       json{{"device", "interop"}, {"members", {"p_stream", "w_state", "ev_values"}}, {"directory", dir.path.string()}});
    REQUIRE(r.status == 201);
    CHECK(r.body["state"] == "recording");
    CHECK(r.body["members"] == json({"p_stream", "w_state", "ev_values"}));
    const auto id = r.body["id"].get<std::uint64_t>();
    REQUIRE(gateway_pipes_open(gw, 1));
    // The device sends the packets and events before its reply, on the same connection: recorded once
    // the reply is here.
    REQUIRE(http_post(gw.port(), "/api/devices/interop/functions/send_stream", json{{"args", {5}}}).status == 200);
    REQUIRE(http_post(gw.port(), "/api/devices/interop/functions/fire_events", json{{"args", {3}}}).status == 200);
    // w_state ticks every 200 ms: 20 messages are 10 values, of which at most 5 packets and 3 events.
    REQUIRE(written_at_least(gw, id, 2 * (5 + 3 + 2)));
    auto stopped = http_post(gw.port(), "/api/recordings/" + std::to_string(id) + "/stop", json::object());
    REQUIRE(stopped.status == 200);
    CHECK(stopped.body["state"] == "stopped");
    CHECK(stopped.body["drops"] == 0);
    REQUIRE(stopped.body["files"].size() == 1);

    rr::mcap::Summary summary;
    auto msgs = read_recording(stopped.body["files"][0].get<std::string>(), &summary);
    REQUIRE(msgs["interop/p_stream json"].size() == 5);
    REQUIRE(msgs["interop/p_stream robotraconteur"].size() == 5);
    for (int i = 0; i < 5; ++i) CHECK(json::parse(text_of(msgs["interop/p_stream json"][i]))["value"] == json({i, i * 0.5}));
    REQUIRE(msgs["interop/ev_values json"].size() == 3);
    auto ev = json::parse(text_of(msgs["interop/ev_values json"][2]));
    CHECK(ev["args"]["seq"] == 2);
    CHECK(msgs["interop/w_state json"].size() >= 2);
    // A wire value's publish_time is the device's packettime, its log_time the gateway's receive time.
    for (const auto& m : msgs["interop/w_state robotraconteur"]) CHECK(m.publish_time <= m.log_time + 1'000'000'000ull);
    bool servicedef = false;
    for (const auto& [sid, s] : summary.schemas)
        if (s.encoding == "robotraconteur_servicedef" && s.name == "experimental.interop_test") servicedef = true;
    CHECK(servicedef);
    for (const auto& [cid, c] : summary.channels) {
        CHECK(c.metadata.at("device") == "interop");
        if (c.message_encoding == "json") CHECK(summary.schemas.at(c.schema_id).encoding == "jsonschema");
    }
    // The recording stays listed, stopped.
    auto list = http_get(gw.port(), "/api/recordings");
    REQUIRE(list.status == 200);
    CHECK(list.body["recordings"][0]["state"] == "stopped");
}

TEST_CASE("recording: members below the root by path, read back, and served again by a replay") {
    RR_SKIP_WITHOUT_INTEROP_SERVICE();
    InteropProcess device;
    TestGateway gw(device.url());
    RecordingDir dir;
    // Two objrefs deep, a string index with characters RR encodes, an int32 index below zero.
    const std::string key = "with space_and-dash", enc = rr::encode_service_path_index(std::string_view(key));
    auto r = http_post(gw.port(), "/api/recordings",
                       json{{"device", "interop"},
                            {"members", {"child_by_name[" + key + "].value", "child_by_name[" + key + "].leaf.x", "child_by_int[-1].name"}},
                            {"directory", dir.path.string()},
                            {"property_period_ms", 100}});
    INFO(r.body.dump());
    REQUIRE(r.status == 201);
    const json names = {"child_by_name[" + enc + "].value", "child_by_name[" + enc + "].leaf.x", "child_by_int[%2d1].name"};
    CHECK(r.body["members"] == names);
    // Polled every 100 ms, the three at once; a round starts when the last one's replies are in: 12
    // messages are at least two rounds, every member in both encodings.
    REQUIRE(written_at_least(gw, r.body["id"].get<std::uint64_t>(), 12));
    auto stopped = http_post(gw.port(), "/api/recordings/" + r.body["id"].dump() + "/stop", json::object());
    REQUIRE(stopped.status == 200);
    REQUIRE(stopped.body["files"].size() == 1);
    const auto file = stopped.body["files"][0].get<std::string>();

    rr::mcap::Summary summary;
    auto msgs = read_recording(file, &summary);
    const std::string value_topic = "interop/child_by_name[" + enc + "]/value", x_topic = "interop/child_by_name[" + enc + "].leaf/x",
                      name_topic = "interop/child_by_int[%2d1]/name";
    REQUIRE(!msgs[value_topic + " json"].empty());
    REQUIRE(!msgs[x_topic + " json"].empty());
    REQUIRE(!msgs[name_topic + " robotraconteur"].empty());
    CHECK(json::parse(text_of(msgs[value_topic + " json"].back()))["value"] == 201);  // the interop service's value of that child
    CHECK(json::parse(text_of(msgs[x_topic + " json"].back()))["value"] == 201.5);
    CHECK(json::parse(text_of(msgs[name_topic + " json"].back()))["value"] == "child[-1]");
    std::map<std::string, std::string> path_of, type_of;
    for (const auto& [cid, c] : summary.channels) {
        CHECK(c.metadata.at("root_type") == "experimental.interop_test.Root");
        path_of[c.topic] = c.metadata.at("path");
        type_of[c.topic] = c.metadata.at("object_type");
        if (c.message_encoding == "robotraconteur") CHECK(summary.schemas.at(c.schema_id).name == "experimental.interop_test");
    }
    CHECK(summary.channels.size() == 6);
    CHECK(path_of[value_topic] == "child_by_name[" + enc + "]");
    CHECK(type_of[value_topic] == "experimental.interop_test.Child");
    CHECK(path_of[x_topic] == "child_by_name[" + enc + "].leaf");
    CHECK(type_of[x_topic] == "experimental.interop_test.Leaf");
    CHECK(path_of[name_topic] == "child_by_int[%2d1]");

    // The replay serves the recorded objects through the objrefs, and only those.
    auto replay = rr::server::record::ReplayDevice::open({file, "again"});
    REQUIRE(replay);
    auto members = (*replay)->status().members;
    std::sort(members.begin(), members.end());
    std::vector<std::string> want = {names[0].get<std::string>(), names[1].get<std::string>(), names[2].get<std::string>()};
    std::sort(want.begin(), want.end());
    CHECK(members == want);
    const auto& root = (*replay)->service()->root();
    auto child = root->resolve_objref({}, "child_by_name", key, true);
    REQUIRE(child);
    CHECK((*child)->type() == "experimental.interop_test.Child");
    auto leaf = (*child)->resolve_objref({}, "leaf", "", false);
    REQUIRE(leaf);
    CHECK((*leaf)->type() == "experimental.interop_test.Leaf");
    REQUIRE(root->resolve_objref({}, "child_by_int", "-1", true));
    auto other = root->resolve_objref({}, "child_by_name", "alpha", true);
    REQUIRE_FALSE(other);
    CHECK(other.error().type == rr::MessageErrorType::ObjectNotFound);
    CHECK_THAT(other.error().message, Catch::Contains("child_by_name[alpha]") && Catch::Contains("was not recorded"));
    CHECK_FALSE(root->resolve_objref({}, "child_by_int", "7", true));
    CHECK_FALSE(root->resolve_objref({}, "child", "", false));  // an objref none of whose objects was recorded
    (*replay)->stop();
}

TEST_CASE("recording: rotation by size keeps the disk budget") {
    RR_SKIP_WITHOUT_INTEROP_SERVICE();
    InteropProcess device;
    TestGateway gw(device.url());
    RecordingDir dir;
    auto r = http_post(gw.port(), "/api/recordings",
                       json{{"device", "interop"}, {"members", {"p_stream"}}, {"directory", dir.path.string()},
                            {"max_file_bytes", 20000}, {"max_total_bytes", 60000}, {"chunk_bytes", 4096}, {"compression", "none"}});
    REQUIRE(r.status == 201);
    REQUIRE(gateway_pipes_open(gw, 1));
    for (std::uint64_t i = 0; i < 6; ++i) {
        REQUIRE(http_post(gw.port(), "/api/devices/interop/functions/send_stream", json{{"args", {200}}}).status == 200);
        // Written before the next burst (200 packets, each in both encodings): the files grow step by step.
        REQUIRE(written_at_least(gw, r.body["id"].get<std::uint64_t>(), 400 * (i + 1)));
    }
    auto stopped = http_post(gw.port(), "/api/recordings/" + r.body["id"].dump() + "/stop", json::object());
    REQUIRE(stopped.status == 200);
    const auto files = stopped.body["files"];
    INFO(stopped.body.dump());
    CHECK(files.size() >= 2);
    std::uint64_t total = 0;
    for (const auto& f : fs::directory_iterator(dir.path)) total += fs::file_size(f.path());
    CHECK(total <= 60000 + 20000);  // the budget, plus the chunk that may overshoot the open file
    CHECK(stopped.body["bytes"].get<std::uint64_t>() == total);
    // Each file is complete on its own.
    for (const auto& f : files) CHECK(read_recording(f.get<std::string>()).count("interop/p_stream json") == 1);
}

TEST_CASE("recording: bad requests are clear errors") {
    RR_SKIP_WITHOUT_INTEROP_SERVICE();
    InteropProcess device;
    TestGateway gw(device.url());
    auto unknown = http_post(gw.port(), "/api/recordings", json{{"device", "nope"}});
    CHECK(unknown.status == 404);
    auto member = http_post(gw.port(), "/api/recordings", json{{"device", "interop"}, {"members", {"no_such"}}});
    CHECK(member.status == 400);
    CHECK(member.body["error"]["message"].get<std::string>().find("no_such") != std::string::npos);
    auto function = http_post(gw.port(), "/api/recordings", json{{"device", "interop"}, {"members", {"send_stream"}}});
    CHECK(function.status == 400);
    CHECK(function.body["error"]["message"].get<std::string>().find("a function") != std::string::npos);
    auto key = http_post(gw.port(), "/api/recordings", json{{"device", "interop"}, {"speed", 3}});
    CHECK(key.status == 400);
    CHECK(http_post(gw.port(), "/api/recordings/77/stop", json::object()).status == 404);
    CHECK(http_get(gw.port(), "/api/recordings/x").status == 404);
}
