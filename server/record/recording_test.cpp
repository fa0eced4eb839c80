// Recording against a real device (rr_interop_service behind a Gateway): a pipe, a wire and an event
// recorded through POST /api/recordings, read back with McapReader: channels, schemas, the pipe
// packets' values in both encodings; members below the root named by path (channels, metadata, and a
// ReplayDevice of the file serving those objects through the objrefs); rotation by size with a disk
// budget; a stop answering with the final status; bad requests. Issue 52: requests stay inside the
// recordings root (no absolute or `..` directory, no NUL in a prefix, no planted link followed), unique
// files for one prefix in one second, max_active (429), the root's budget (507), queue_bytes' bound, the
// ended statuses kept, the writer's index bounded by rotation.
#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>

#include "core/mcap/mcap_reader.hpp"
#include "server/gateway/json_api_test_fixture.hpp"
#include "base/names/service_path.hpp"
#include "server/gateway/mirror_service.hpp"
#include "server/gateway/session_endpoints.hpp"
#include "server/mcap/mcap_file.hpp"
#include "server/record/recording.hpp"
#include "server/record/recordings.hpp"
#include "server/record/replay_device.hpp"
#include "test/support/eventually.hpp"
#include "test/support/temp_dir.hpp"

using namespace rr::server::gateway::testing;
namespace fs = std::filesystem;

namespace {

struct RecordingDir : rr::testing::TempDir {
    RecordingDir() : rr::testing::TempDir("rr-recording-test") {}
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

// The gateway's configuration with its recordings root in `dir` (and `settings` changed as given).
std::function<void(rr::server::app::GatewayConfig&)> root_in(const RecordingDir& dir,
                                                              std::function<void(rr::server::record::RecordingsSettings&)> settings = {}) {
    return [path = dir.path.string(), settings](rr::server::app::GatewayConfig& c) {
        c.recordings.root = path;
        if (settings) settings(c.recordings);
    };
}

std::string file_text(const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(f), {});
}

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
    RecordingDir dir;
    TestGateway gw(device.url(), true, {}, root_in(dir));
    auto r = http_post(gw.port(), "/api/recordings",
                       json{{"device", "interop"}, {"members", {"p_stream", "w_state", "ev_values"}}, {"directory", "lab/run1"}});
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
    const auto file = stopped.body["files"][0].get<std::string>();
    CHECK(fs::path(file).parent_path() == dir.path / "lab/run1");  // in the sub-folder of the root

    rr::mcap::Summary summary;
    auto msgs = read_recording(file, &summary);
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
    RecordingDir dir;
    TestGateway gw(device.url(), true, {}, root_in(dir));
    // Two objrefs deep, a string index with characters RR encodes, an int32 index below zero.
    const std::string key = "with space_and-dash", enc = rr::encode_service_path_index(std::string_view(key));
    auto r = http_post(gw.port(), "/api/recordings",
                       json{{"device", "interop"},
                            {"members", {"child_by_name[" + key + "].value", "child_by_name[" + key + "].leaf.x", "child_by_int[-1].name"}},
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
    rr::server::record::ReplayOptions replay_options;
    replay_options.file = file;
    replay_options.name = "again";
    auto replay = rr::server::record::ReplayDevice::open(replay_options);
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
    RecordingDir dir;
    TestGateway gw(device.url(), true, {}, root_in(dir));
    auto r = http_post(gw.port(), "/api/recordings",
                       json{{"device", "interop"}, {"members", {"p_stream"}},
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

// --- issue 52: recordings stay in their place, and their memory is bounded ----------------------------

TEST_CASE("recording: a request's directory and prefix stay inside the recordings root") {
    RR_SKIP_WITHOUT_INTEROP_SERVICE();
    InteropProcess device;
    RecordingDir dir, outside;
    TestGateway gw(device.url(), true, {}, root_in(dir));
    const auto victim = outside.path / "victim.txt";
    { std::ofstream(victim) << "precious"; }
    auto post = [&](json body) {
        body["device"] = "interop";
        body["members"] = {"w_state"};
        body["duration_s"] = 2;
        return http_post(gw.port(), "/api/recordings", body);
    };
    // The request: the prefix was cut at the NUL, the file opened without O_EXCL, and the victim
    // file replaced by an MCAP file.
    auto nul = post(json{{"directory", outside.path.string()}, {"prefix", std::string("victim.txt\0", 11)},
                         {"encoding", "robotraconteur"}, {"compression", "none"}});
    CHECK(nul.status == 400);
    auto nul_only = post(json{{"prefix", std::string("victim.txt\0", 11)}});
    CHECK(nul_only.status == 400);
    CHECK_THAT(nul_only.body["error"]["message"].get<std::string>(), Catch::Contains("\\u0000"));
    auto absolute = post(json{{"directory", outside.path.string()}});
    CHECK(absolute.status == 400);
    CHECK_THAT(absolute.body["error"]["message"].get<std::string>(), Catch::Contains("is an absolute path"));
    auto up = post(json{{"directory", "../" + outside.path.filename().string()}});
    CHECK(up.status == 400);
    CHECK_THAT(up.body["error"]["message"].get<std::string>(), Catch::Contains("starting with a dot"));
    CHECK(file_text(victim) == "precious");
    CHECK(std::distance(fs::directory_iterator(outside.path), fs::directory_iterator()) == 1);
    CHECK(http_get(gw.port(), "/api/recordings").body["recordings"].empty());  // refused, not listed
}

TEST_CASE("recording: a symbolic link planted in the root is not followed, folder or file") {
    RR_SKIP_WITHOUT_INTEROP_SERVICE();
    InteropProcess device;
    RecordingDir dir, outside;
    TestGateway gw(device.url(), true, {}, root_in(dir));
    const auto victim = outside.path / "victim.txt";
    { std::ofstream(victim) << "precious"; }
    fs::create_directory_symlink(outside.path, dir.path / "lab");
    auto linked = http_post(gw.port(), "/api/recordings", json{{"device", "interop"}, {"members", {"w_state"}}, {"directory", "lab/run"}});
    CHECK(linked.status == 507);
    CHECK_THAT(linked.body["error"]["message"].get<std::string>(), Catch::Contains("lab is a symbolic link"));
    CHECK_FALSE(fs::exists(outside.path / "run"));
    auto listed = http_get(gw.port(), "/api/recordings").body["recordings"];
    REQUIRE(listed.size() == 1);  // listed as failed, with the reason
    CHECK(listed[0]["state"] == "failed");

    // Links where this second's and the next minute's first files would go (a bound on a slow start
    // under load, not its expected time): the file gets another name.
    fs::create_directory(dir.path / "cams");
    const auto now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
    for (int s = 0; s < 60; ++s) {
        std::tm tm{};
        const std::time_t t = now + s;
        gmtime_r(&t, &tm);
        char stamp[32];
        std::strftime(stamp, sizeof stamp, "%Y%m%dT%H%M%SZ", &tm);
        fs::create_symlink(victim, dir.path / "cams" / (std::string("cam-") + stamp + "-001.mcap"));
    }
    auto r = http_post(gw.port(), "/api/recordings",
                       json{{"device", "interop"}, {"members", {"w_state"}}, {"directory", "cams"}, {"prefix", "cam"}});
    REQUIRE(r.status == 201);
    std::this_thread::sleep_for(300ms);
    auto stopped = http_post(gw.port(), "/api/recordings/" + r.body["id"].dump() + "/stop", json::object());
    REQUIRE(stopped.status == 200);
    REQUIRE(stopped.body["files"].size() == 1);
    const auto file = stopped.body["files"][0].get<std::string>();
    CHECK_THAT(file, Catch::EndsWith("-001-2.mcap"));
    CHECK_FALSE(fs::is_symlink(file));
    CHECK(file_text(victim) == "precious");
    read_recording(file);
}

TEST_CASE("recording: one prefix started in the same second never shares a file, and past max_active it is 429") {
    RR_SKIP_WITHOUT_INTEROP_SERVICE();
    InteropProcess device;
    RecordingDir dir;
    TestGateway gw(device.url(), true, {}, root_in(dir, [](auto& s) { s.max_active = 6; }));
    std::vector<std::thread> clients;
    std::mutex m;
    std::vector<HttpReply> replies;
    for (int i = 0; i < 10; ++i)
        clients.emplace_back([&] {
            auto r = http_post(gw.port(), "/api/recordings", json{{"device", "interop"}, {"members", {"w_state"}}, {"prefix", "same"}});
            std::lock_guard<std::mutex> lock(m);
            replies.push_back(std::move(r));
        });
    for (auto& t : clients) t.join();
    std::vector<std::uint64_t> ids;
    std::size_t refused = 0;
    for (const auto& r : replies) {
        INFO(r.body.dump());
        if (r.status == 201) ids.push_back(r.body["id"].get<std::uint64_t>());
        else {
            CHECK(r.status == 429);
            CHECK_THAT(r.body["error"]["message"].get<std::string>(), Catch::Contains("recordings.max_active"));
            ++refused;
        }
    }
    CHECK(ids.size() == 6);
    CHECK(refused == 4);
    std::this_thread::sleep_for(500ms);  // w_state ticks every 200 ms
    std::set<std::string> files;
    for (auto id : ids) {
        auto s = http_post(gw.port(), "/api/recordings/" + std::to_string(id) + "/stop", json::object());
        REQUIRE(s.status == 200);
        REQUIRE(s.body["files"].size() == 1);
        files.insert(s.body["files"][0].get<std::string>());
    }
    CHECK(files.size() == ids.size());  // no two recordings in one file
    for (const auto& f : files) {
        auto msgs = read_recording(f);
        CHECK(msgs.count("interop/w_state json") == 1);
    }
    // Ended, they no longer count: another starts.
    auto again = http_post(gw.port(), "/api/recordings", json{{"device", "interop"}, {"members", {"w_state"}}, {"prefix", "same"}});
    CHECK(again.status == 201);
}

TEST_CASE("recording: the root's disk budget refuses a recording that would pass it (507)") {
    RR_SKIP_WITHOUT_INTEROP_SERVICE();
    InteropProcess device;
    RecordingDir dir;
    TestGateway gw(device.url(), true, {}, root_in(dir, [](auto& s) { s.max_total_bytes = 3u << 20; }));
    { std::ofstream(dir.path / "old.mcap", std::ios::binary) << std::string(2500000, 'x'); }
    auto own = http_post(gw.port(), "/api/recordings",
                         json{{"device", "interop"}, {"members", {"w_state"}}, {"max_total_bytes", 1u << 20}, {"max_file_bytes", 65536}});
    CHECK(own.status == 507);
    CHECK_THAT(own.body["error"]["message"].get<std::string>(),
               Catch::Contains("would pass its budget of 3145728 bytes") && Catch::Contains("2500000 bytes used"));
    auto unbounded = http_post(gw.port(), "/api/recordings", json{{"device", "interop"}, {"members", {"w_state"}}});
    CHECK(unbounded.status == 507);
    CHECK(http_get(gw.port(), "/api/recordings").body["recordings"].empty());  // refusals are not listed
    fs::remove(dir.path / "old.mcap");
    auto fits = http_post(gw.port(), "/api/recordings",
                          json{{"device", "interop"}, {"members", {"w_state"}}, {"max_total_bytes", 1u << 20}, {"max_file_bytes", 65536}});
    CHECK(fits.status == 201);
    // Its 1 MiB is set aside: a second one asking 2.5 MiB does not fit beside it.
    auto second = http_post(gw.port(), "/api/recordings",
                            json{{"device", "interop"}, {"members", {"w_state"}}, {"max_total_bytes", 2500000}, {"max_file_bytes", 65536}});
    CHECK(second.status == 507);
    CHECK_THAT(second.body["error"]["message"].get<std::string>(), Catch::Contains("set aside by running recordings"));
}

TEST_CASE("recording: queue_bytes over recordings.max_queue_bytes is refused (400)") {
    RR_SKIP_WITHOUT_INTEROP_SERVICE();
    InteropProcess device;
    RecordingDir dir;
    TestGateway gw(device.url(), true, {}, root_in(dir));
    auto r = http_post(gw.port(), "/api/recordings", json{{"device", "interop"}, {"members", {"w_state"}}, {"queue_bytes", 1000000000000ull}});
    CHECK(r.status == 400);
    CHECK_THAT(r.body["error"]["message"].get<std::string>(), Catch::Contains("recordings.max_queue_bytes"));
    auto ok = http_post(gw.port(), "/api/recordings", json{{"device", "interop"}, {"members", {"w_state"}}, {"queue_bytes", 256u << 20}});
    CHECK(ok.status == 201);
}

TEST_CASE("recording: ended recordings keep only their status, the last keep_ended of them") {
    RR_SKIP_WITHOUT_INTEROP_SERVICE();
    InteropProcess device;
    RecordingDir dir;
    TestGateway gw(device.url(), true, {}, root_in(dir, [](auto& s) { s.keep_ended = 3; }));
    std::vector<std::uint64_t> ids;
    for (int i = 0; i < 6; ++i) {
        auto r = http_post(gw.port(), "/api/recordings", json{{"device", "interop"}, {"members", {"w_state"}}});
        REQUIRE(r.status == 201);
        ids.push_back(r.body["id"].get<std::uint64_t>());
        REQUIRE(http_post(gw.port(), "/api/recordings/" + std::to_string(ids.back()) + "/stop", json::object()).status == 200);
    }
    auto running = http_post(gw.port(), "/api/recordings", json{{"device", "interop"}, {"members", {"w_state"}}});
    REQUIRE(running.status == 201);
    // The list is the running one and the last three ended (the ended listener runs just after the stop
    // answer: wait for it, bounded).
    json list;
    for (int i = 0; i < 200; ++i) {
        list = http_get(gw.port(), "/api/recordings").body["recordings"];
        if (list.size() == 4) break;
        std::this_thread::sleep_for(50ms);
    }
    REQUIRE(list.size() == 4);
    std::vector<std::uint64_t> listed;
    for (const auto& s : list) listed.push_back(s["id"].get<std::uint64_t>());
    CHECK(listed == std::vector<std::uint64_t>{ids[3], ids[4], ids[5], running.body["id"].get<std::uint64_t>()});
    CHECK(http_get(gw.port(), "/api/recordings/" + std::to_string(ids[0])).status == 404);
    CHECK(gw.gateway().recordings()->active() == 1);  // the ended ones hold no Recording (threads, queue, buffers)
}

TEST_CASE("recording: the writer's index is bounded: a new file when it passes max_index_bytes") {
    RR_SKIP_WITHOUT_INTEROP_SERVICE();
    InteropProcess device;
    RecordingDir dir;
    TestGateway gw(device.url(), true, {}, root_in(dir));
    rr::server::record::RecordingSpec spec;
    spec.device = "interop";
    spec.members = {"p_stream"};
    spec.chunk_bytes = 1024;  // a chunk every few packets: the index grows quickly
    spec.max_index_bytes = 2000;
    auto root = std::make_shared<rr::server::record::RecordingsRoot>(dir.path.string(), 0);
    auto rec = rr::server::record::Recording::start(1, spec, gw.gateway().devices().front(), gw.api(), root);
    INFO((rec ? std::string() : rec.error().message));
    REQUIRE(rec);
    std::this_thread::sleep_for(300ms);  // the gateway's pipe endpoint is open
    REQUIRE(http_post(gw.port(), "/api/devices/interop/functions/send_stream", json{{"args", {300}}}).status == 200);
    // Wait for the packets to be written (the writer takes them at least every 50 ms), bounded.
    for (int i = 0; i < 400 && (*rec)->status().messages < 600; ++i) std::this_thread::sleep_for(50ms);
    (*rec)->stop();
    (*rec)->wait();
    const auto s = (*rec)->status();
    INFO(status_json(s).dump());
    CHECK(s.state == rr::server::record::RecordingState::stopped);
    CHECK(s.messages == 600);
    CHECK(s.files.size() >= 3);
    std::size_t packets = 0;
    for (const auto& f : s.files) {
        rr::mcap::Summary summary;
        auto msgs = read_recording(f, &summary);
        // Each file's chunk indexes stay near the bound (one chunk index past it at most).
        std::size_t index = 0;
        for (const auto& ci : summary.chunk_indexes) index += rr::mcap::memory_of(ci);
        CHECK(index < 2000 + 1000);
        packets += msgs["interop/p_stream json"].size();
    }
    CHECK(packets == 300);
}

namespace {

// A format a test registers: per member one channel `<topic>/fake` (its own schema, added once a file,
// and the member's metadata), each entry as "<member> <entry type> <n>" with n counted per member.
class FakeEncoder : public rr::server::record::FormatEncoder {
public:
    explicit FakeEncoder(const rr::server::record::FormatContext& context) : context_(context), counts_(context.members.size(), 0) {}
    rr::Result<void> open_file(rr::server::record::FormatFile& file) override {
        auto schema = file.add_schema("fake.Count", "text", "a member's entries, counted");
        if (!schema) return schema.take_error();
        channels_.clear();
        for (const auto& m : context_.members) {
            auto id = file.add_channel(*schema, m.topic + "/fake", "fake", m.metadata);
            if (!id) return id.take_error();
            channels_.push_back(*id);
        }
        return {};
    }
    rr::Result<void> write(const rr::server::record::RecordedEntry& e, rr::server::record::MessageOut& out) override {
        const auto& entry = e.entry.entry();
        return out.write(channels_[e.member], entry.member_name + " " + std::to_string(static_cast<int>(entry.entry_type)) + " " +
                                                  std::to_string(counts_[e.member]++));
    }

private:
    const rr::server::record::FormatContext& context_;
    std::vector<std::uint16_t> channels_;
    std::vector<int> counts_;
};

class FakeFormat : public rr::server::record::RecordingFormat {
public:
    std::string_view name() const noexcept override { return "fake"; }
    std::unique_ptr<rr::server::record::FormatEncoder> encoder(const rr::server::record::FormatContext& context) const override {
        return std::make_unique<FakeEncoder>(context);
    }
};

}  // namespace

TEST_CASE("recording: a format registered by a test gets its channels and every entry, Recording unchanged") {
    RR_SKIP_WITHOUT_INTEROP_SERVICE();
    using namespace rr::server::record;
    InteropProcess device;
    RecordingDir dir;
    TestGateway gw(device.url(), true, {}, root_in(dir));
    RecordingFormats formats = builtin_recording_formats();
    formats.push_back(std::make_shared<FakeFormat>());
    RecordingSpec spec;
    spec.device = "interop";
    spec.members = {"p_stream", "ev_values"};
    spec.encodings = {"fake"};
    auto root = std::make_shared<RecordingsRoot>(dir.path.string(), 0);
    // Not a built-in format: refused where only those are known.
    auto unknown = Recording::start(1, spec, gw.gateway().devices().front(), gw.api(), root);
    REQUIRE_FALSE(unknown);
    CHECK(unknown.error().message == "record: encoding: no format \"fake\"");

    auto rec = Recording::start(2, spec, gw.gateway().devices().front(), gw.api(), root, formats);
    INFO((rec ? std::string() : rec.error().message));
    REQUIRE(rec);
    REQUIRE(gateway_pipes_open(gw, 1));
    REQUIRE(http_post(gw.port(), "/api/devices/interop/functions/send_stream", json{{"args", {5}}}).status == 200);
    REQUIRE(http_post(gw.port(), "/api/devices/interop/functions/fire_events", json{{"args", {3}}}).status == 200);
    REQUIRE(rr::testing::eventually([&] { return (*rec)->status().messages >= 8; }));
    (*rec)->stop();
    (*rec)->wait();
    const auto s = (*rec)->status();
    CHECK(s.state == RecordingState::stopped);
    CHECK(s.messages == 8);
    REQUIRE(s.files.size() == 1);

    rr::mcap::Summary summary;
    auto msgs = read_recording(s.files[0], &summary);
    CHECK(msgs.size() == 2);  // the fake channels only: no json, robotraconteur or Foxglove channel
    REQUIRE(msgs["interop/p_stream/fake fake"].size() == 5);
    REQUIRE(msgs["interop/ev_values/fake fake"].size() == 3);
    const auto pipe_packet = std::to_string(static_cast<int>(rr::MessageEntryType::PipePacket));
    const auto event = std::to_string(static_cast<int>(rr::MessageEntryType::EventReq));
    for (int i = 0; i < 5; ++i) CHECK(text_of(msgs["interop/p_stream/fake fake"][i]) == "p_stream " + pipe_packet + " " + std::to_string(i));
    for (int i = 0; i < 3; ++i) CHECK(text_of(msgs["interop/ev_values/fake fake"][i]) == "ev_values " + event + " " + std::to_string(i));
    // The channels carry the member's metadata (channel_metadata.hpp), the file the device's definitions.
    std::set<std::string> kinds;
    for (const auto& [cid, c] : summary.channels) {
        CHECK(c.metadata.at(channel_key::device) == "interop");
        CHECK(summary.schemas.at(c.schema_id).name == "fake.Count");
        kinds.insert(c.metadata.at(channel_key::kind));
    }
    CHECK(kinds == std::set<std::string>{"pipe", "event"});
    bool servicedef = false;
    for (const auto& [sid, sc] : summary.schemas)
        if (sc.encoding == kServiceDefinitionSchemaEncoding && sc.name == "experimental.interop_test") servicedef = true;
    CHECK(servicedef);
}
