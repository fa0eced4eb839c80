// GET /api/devices/{name}/access (json_access.hpp): what the caller's gateway roles allow on each
// member of a device's root object, against rr_interop_service behind a Gateway with users and roles
// (and without any), and that the answer agrees with what the gateway then does with the requests.
#include <filesystem>
#include <fstream>
#include <set>
#include <utility>

#include "server/gateway/json_api_installer.hpp"
#include "server/gateway/json_api_test_fixture.hpp"
#include "server/service/password_table.hpp"

using namespace rr;
using namespace rr::server;
using namespace rr::server::gateway;
using namespace rr::server::gateway::testing;

// Named, not anonymous: the TSan preset builds the tests as unity files.
namespace json_access_test {

/// One request with an optional Cookie header and body.
HttpReply request_as(std::uint16_t port, bhttp::verb method, const std::string& target, const std::string& cookie,
                     const std::string& body = {}) {
    boost::asio::io_context io;
    beast::tcp_stream s(io);
    s.connect(tcp::endpoint(boost::asio::ip::make_address("127.0.0.1"), port));
    bhttp::request<bhttp::string_body> req{method, target, 11};
    req.set(bhttp::field::host, "localhost");
    if (!cookie.empty()) req.set(bhttp::field::cookie, cookie);
    if (!body.empty()) {
        req.set(bhttp::field::content_type, "application/json");
        req.body() = body;
    }
    req.prepare_payload();
    bhttp::write(s, req);
    beast::flat_buffer b;
    HttpReply r;
    bhttp::response_parser<bhttp::string_body> parser;
    bhttp::read(s, b, parser);
    r.raw = parser.release();
    r.status = r.raw.result_int();
    r.body = json::parse(r.raw.body(), nullptr, false);
    return r;
}

/// Device "interop" (auth: shared) and "pt" (auth: passthrough), both rr_interop_service, behind a
/// gateway with users alice (operator: everything, lock too), victor (viewer: read everything) and dora
/// (driver: call `add`, read `p_double` and `ro_*`, lock the object `child`, on both devices only).
struct AuthGateway {
    std::filesystem::path dir =
        std::filesystem::temp_directory_path() / ("rr_json_access_" + std::to_string(::getpid()));
    std::unique_ptr<app::Gateway> gateway;

    explicit AuthGateway(const std::string& url) {
        std::filesystem::create_directories(dir);
        {
            std::ofstream users(dir / "users.txt");
            users << "alice " << PasswordTable::md5_hex("alice-pw") << " operator\n";
            users << "victor " << PasswordTable::md5_hex("victor-pw") << " viewer\n";
            users << "dora " << PasswordTable::md5_hex("dora-pw") << " driver,objectlock\n";
        }
        app::GatewayConfig cfg;
        cfg.local = false;
        cfg.port = 0;
        cfg.listen = "127.0.0.1";
        cfg.demo = false;
        cfg.threads = 2;
        for (const char* name : {"interop", "pt"}) {
            DeviceConfig d;
            d.name = name;
            d.url = url;
            d.backoff_initial = std::chrono::milliseconds(100);
            d.backoff_max = std::chrono::milliseconds(200);
            if (std::string(name) == "pt") d.auth = DeviceAuth::passthrough;
            cfg.devices.push_back(d);
        }
        using Rule = app::GatewayAuthConfig::Rule;
        cfg.auth.users = (dir / "users.txt").string();
        cfg.auth.roles.push_back({"operator", {Rule{{"*"}, {"*"}, true, true, true, true}}});
        cfg.auth.roles.push_back({"viewer", {Rule{{"*"}, {"*"}, true, false, false}}});
        cfg.auth.roles.push_back({"driver", {Rule{{"interop", "pt"}, {"add"}, false, false, true},
                                             Rule{{"interop", "pt"}, {"p_double", "ro_*"}, true, false, false},
                                             Rule{{"interop", "pt"}, {"child"}, false, false, false, true}}});
        auto g = app::Gateway::start(cfg, {}, install_json_api);
        INFO((g ? std::string() : g.error().message));
        REQUIRE(g);
        gateway = std::move(*g);
        const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(30);  // a bound on a hang
        auto connected = [&] {
            for (const auto& d : gateway->devices())
                if (d->status().state != DeviceState::connected) return false;
            return true;
        };
        while (!connected() && std::chrono::steady_clock::now() < until) std::this_thread::sleep_for(std::chrono::milliseconds(10));
        REQUIRE(connected());
    }
    ~AuthGateway() {
        if (gateway) gateway->stop();
        gateway.reset();
        std::error_code ec;
        std::filesystem::remove_all(dir, ec);
    }

    std::uint16_t port() const { return gateway->port(); }

    /// The session cookie (`rrgw_session=…`) of a password login.
    std::string login(const std::string& user, const std::string& password) const {
        auto r = request_as(port(), bhttp::verb::post, "/api/login", {}, json{{"username", user}, {"password", password}}.dump());
        REQUIRE(r.status == 200);
        const std::string set_cookie(r.raw[bhttp::field::set_cookie]);
        REQUIRE(set_cookie.rfind("rrgw_session=", 0) == 0);
        return set_cookie.substr(0, set_cookie.find(';'));
    }
};

std::string error_name_of(const HttpReply& r) {
    if (!r.body.is_object() || !r.body.contains("error")) return "<no error: " + r.raw.body() + ">";
    return r.body["error"]["name"].get<std::string>();
}

std::set<std::string> root_member_names(std::uint16_t port, const std::string& cookie) {
    auto info = request_as(port, bhttp::verb::get, "/api/devices/interop", cookie);
    REQUIRE(info.status == 200);
    std::set<std::string> out;
    for (const auto& m : info.body["members"]) out.insert(m["name"].get<std::string>());
    REQUIRE(out.count("add") == 1);
    return out;
}

bool lists(const json& ops, const char* op) {
    for (const auto& o : ops)
        if (o == op) return true;
    return false;
}

}  // namespace json_access_test
using namespace json_access_test;

TEST_CASE("json access: without gateway logins the answer says the gateway checks nothing") {
    RR_SKIP_WITHOUT_INTEROP_SERVICE();
    InteropProcess device;
    TestGateway gw(device.url());
    auto r = http_get(gw.port(), "/api/devices/interop/access");
    REQUIRE(r.status == 200);
    CHECK(r.body == json{{"device", "interop"}, {"auth", false}, {"user", nullptr}, {"members", nullptr},
                         {"lock", nullptr}, {"record", true}});
    CHECK(http_get(gw.port(), "/api/devices/interop/access?members=add").body["members"].is_null());
    auto missing = http_get(gw.port(), "/api/devices/nosuch/access");
    CHECK(missing.status == 404);
    CHECK(error_name_of(missing) == "RobotRaconteur.ServiceNotFound");
    // device_user is for passthrough devices only, with or without logins.
    auto shared = http_get(gw.port(), "/api/devices/interop/access?device_user=alice");
    CHECK(shared.status == 400);
    CHECK_THAT(shared.body["error"]["message"].get<std::string>(), Catch::Contains("auth: passthrough devices only"));
    auto post = http_post(gw.port(), "/api/devices/interop/access", json::object());
    CHECK(post.status == 405);
    CHECK(post.raw[bhttp::field::allow] == "GET");
}

TEST_CASE("json access: each role's operations on every root member, ?members, errors") {
    RR_SKIP_WITHOUT_INTEROP_SERVICE();
    InteropProcess device;
    AuthGateway gw(device.url());
    const auto port = gw.port();

    // Not logged in: 401 as every other device route.
    auto anonymous = request_as(port, bhttp::verb::get, "/api/devices/interop/access", {});
    CHECK(anonymous.status == 401);
    CHECK(anonymous.raw[bhttp::field::www_authenticate] == "Bearer");
    CHECK(error_name_of(anonymous) == "RobotRaconteur.AuthenticationError");

    const auto alice = gw.login("alice", "alice-pw");
    const auto victor = gw.login("victor", "victor-pw");
    const auto dora = gw.login("dora", "dora-pw");
    const auto names = root_member_names(port, alice);

    SECTION("operator: read, write and call on every member") {
        auto r = request_as(port, bhttp::verb::get, "/api/devices/interop/access", alice);
        REQUIRE(r.status == 200);
        CHECK(r.body["device"] == "interop");
        CHECK(r.body["auth"] == true);
        CHECK(r.body["user"] == "alice");
        CHECK(r.body["roles"] == json{"operator"});
        CHECK(r.body["device_user"].is_null());
        REQUIRE(r.body["members"].is_object());
        std::set<std::string> listed;
        for (auto it = r.body["members"].begin(); it != r.body["members"].end(); ++it) {
            listed.insert(it.key());
            CHECK(it.value() == json{"read", "write", "call"});
        }
        CHECK(listed == names);
        CHECK(r.body["lock"] == true);
    }
    SECTION("viewer: read only") {
        auto r = request_as(port, bhttp::verb::get, "/api/devices/interop/access", victor);
        REQUIRE(r.status == 200);
        CHECK(r.body["user"] == "victor");
        CHECK(r.body["members"].size() == names.size());
        for (const auto& ops : r.body["members"]) CHECK(ops == json{"read"});
        CHECK(r.body["lock"] == false);
    }
    SECTION("a role allowing some members: the others get an empty list") {
        auto r = request_as(port, bhttp::verb::get, "/api/devices/interop/access", dora);
        REQUIRE(r.status == 200);
        const auto& m = r.body["members"];
        CHECK(m.size() == names.size());
        CHECK(m["add"] == json{"call"});
        CHECK(m["p_double"] == json{"read"});
        CHECK(m["ro_value"] == json{"read"});
        CHECK(m["p_int32"] == json::array());
        CHECK(m["count_up"] == json::array());
        CHECK(r.body["roles"] == json{"driver", "objectlock"});
        CHECK(r.body["lock"] == false);  // `lock` on the object child only, not on the root
    }
    SECTION("?members restricts the answer; an unknown or empty name is 400") {
        auto r = request_as(port, bhttp::verb::get, "/api/devices/interop/access?members=add,p_int32,add", dora);
        REQUIRE(r.status == 200);
        CHECK(r.body["members"] == json{{"add", {"call"}}, {"p_int32", json::array()}});
        auto bad = request_as(port, bhttp::verb::get, "/api/devices/interop/access?members=add,jog_freespace", dora);
        CHECK(bad.status == 400);
        CHECK(error_name_of(bad) == "RobotRaconteur.InvalidArgument");
        CHECK_THAT(bad.body["error"]["message"].get<std::string>(),
                   Catch::Contains("no member \"jog_freespace\"") && Catch::Contains("experimental.interop_test.Root"));
        for (const char* q : {"?members=", "?members=add,", "?members=add,,p_double"}) {
            INFO(q);
            CHECK(request_as(port, bhttp::verb::get, std::string("/api/devices/interop/access") + q, dora).status == 400);
        }
    }
    SECTION("unknown device: 404 once logged in") {
        auto r = request_as(port, bhttp::verb::get, "/api/devices/nosuch/access", dora);
        CHECK(r.status == 404);
        CHECK(error_name_of(r) == "RobotRaconteur.ServiceNotFound");
    }
    SECTION("passthrough: device_user gives the roles of the caller's own name only") {
        auto own = request_as(port, bhttp::verb::get, "/api/devices/pt/access?device_user=dora&members=add,p_double,p_int32", dora);
        REQUIRE(own.status == 200);
        CHECK(own.body["device"] == "pt");
        CHECK(own.body["user"] == "dora");
        CHECK(own.body["device_user"] == "dora");
        CHECK(own.body["members"] == json{{"add", {"call"}}, {"p_double", {"read"}}, {"p_int32", json::array()}});
        // Another name: refused, the same way whether or not it is a gateway user (nothing to learn).
        auto other = request_as(port, bhttp::verb::get, "/api/devices/pt/access?device_user=alice", dora);
        CHECK(other.status == 403);
        CHECK(error_name_of(other) == "RobotRaconteur.PermissionDenied");
        auto nobody = request_as(port, bhttp::verb::get, "/api/devices/pt/access?device_user=nosuchuser", dora);
        CHECK(nobody.status == 403);
        CHECK(nobody.body["error"]["message"].get<std::string>().find("nosuchuser") != std::string::npos);
        CHECK(request_as(port, bhttp::verb::get, "/api/devices/pt/access?device_user=", dora).status == 400);
        // Not on a shared device.
        CHECK(request_as(port, bhttp::verb::get, "/api/devices/interop/access?device_user=dora", dora).status == 400);
        // Without device_user a passthrough device answers for the caller's gateway roles (REST/WebSocket).
        auto plain = request_as(port, bhttp::verb::get, "/api/devices/pt/access?members=add", victor);
        REQUIRE(plain.status == 200);
        CHECK(plain.body["members"] == json{{"add", {"read"}}});
    }
}

TEST_CASE("json access: the answer agrees with what the gateway does with the requests") {
    RR_SKIP_WITHOUT_INTEROP_SERVICE();
    InteropProcess device;
    AuthGateway gw(device.url());
    const auto port = gw.port();
    const std::pair<const char*, const char*> users[] = {{"alice", "alice-pw"}, {"victor", "victor-pw"}, {"dora", "dora-pw"}};
    for (const auto& [user, password] : users) {
        INFO(user);
        const auto cookie = gw.login(user, password);
        auto r = request_as(port, bhttp::verb::get, "/api/devices/interop/access?members=add,p_double,p_int32", cookie);
        REQUIRE(r.status == 200);
        const auto& m = r.body["members"];
        // call: add(2, 3)
        auto called = request_as(port, bhttp::verb::post, "/api/devices/interop/functions/add", cookie, json{{"args", {2, 3}}}.dump());
        CHECK(called.status == (lists(m["add"], "call") ? 200u : 403u));
        if (called.status == 200) CHECK(called.body["return"] == 5);
        // read and write: p_double, p_int32
        for (const char* prop : {"p_double", "p_int32"}) {
            INFO(prop);
            auto got = request_as(port, bhttp::verb::get, std::string("/api/devices/interop/properties/") + prop, cookie);
            CHECK(got.status == (lists(m[prop], "read") ? 200u : 403u));
            auto set = request_as(port, bhttp::verb::put, std::string("/api/devices/interop/properties/") + prop, cookie,
                                  json{{"value", 1}}.dump());
            // allowed: the gateway passes it on (the interop device may refuse the value itself: 502 then,
            // never a 403); refused: 403 PermissionDenied from the gateway
            if (lists(m[prop], "write")) CHECK(set.status != 403u);
            else CHECK(set.status == 403u);
            if (set.status == 403) CHECK(error_name_of(set) == "RobotRaconteur.PermissionDenied");
        }
    }
}

TEST_CASE("json access: the WebSocket's access op answers as the route") {
    RR_SKIP_WITHOUT_INTEROP_SERVICE();
    InteropProcess device;
    AuthGateway gw(device.url());
    WsClient ws(gw.port());
    CHECK(ws.request(json{{"op", "access"}, {"device", "interop"}})["error"]["name"] == "RobotRaconteur.AuthenticationError");
    REQUIRE(ws.request(json{{"op", "login"}, {"username", "dora"}, {"password", "dora-pw"}}).contains("result"));
    auto r = ws.request(json{{"op", "access"}, {"device", "interop"}, {"members", {"add", "p_int32"}}});
    REQUIRE(r.contains("result"));
    CHECK(r["result"]["user"] == "dora");
    CHECK(r["result"]["members"] == json{{"add", {"call"}}, {"p_int32", json::array()}});
    const auto cookie = gw.login("dora", "dora-pw");
    auto rest = request_as(gw.port(), bhttp::verb::get, "/api/devices/interop/access", cookie);
    auto whole = ws.request(json{{"op", "access"}, {"device", "interop"}});
    CHECK(whole["result"] == rest.body);
    auto bad = ws.request(json{{"op", "access"}, {"device", "interop"}, {"members", {"nosuch"}}});
    CHECK(bad["error"]["name"] == "RobotRaconteur.InvalidArgument");
    auto own = ws.request(json{{"op", "access"}, {"device", "pt"}, {"members", {"add"}}, {"device_user", "dora"}});
    CHECK(own["result"]["members"] == json{{"add", {"call"}}});
    CHECK(ws.request(json{{"op", "access"}, {"device", "pt"}, {"device_user", "alice"}})["error"]["name"] ==
          "RobotRaconteur.PermissionDenied");
    CHECK(ws.request(json{{"op", "access"}, {"device", "nosuch"}})["error"]["name"] == "RobotRaconteur.ServiceNotFound");
}
