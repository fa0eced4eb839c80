// The JSON API's REST routes against rr_interop_service behind a Gateway: every value kind both ways,
// functions and generators, wires, objects below the root, and every error status.
#include "server/gateway/json_api_test_fixture.hpp"
#include "test/support/eventually.hpp"

using namespace rr;
using namespace rr::server;
using namespace rr::server::gateway;
using namespace rr::server::gateway::testing;

namespace {

std::string error_name_of(const HttpReply& r) {
    if (!r.body.is_object() || !r.body.contains("error")) return "<no error: " + r.raw.body() + ">";
    return r.body["error"]["name"].get<std::string>();
}

const std::string kProps = "/api/devices/interop/properties/";
const std::string kFuncs = "/api/devices/interop/functions/";

json call(std::uint16_t port, const std::string& fn, const json& body) {
    auto r = http_post(port, kFuncs + fn, body);
    INFO(fn << " " << body.dump() << " -> " << r.raw.body());
    REQUIRE(r.status == 200);
    return r.body;
}

}  // namespace

TEST_CASE("json api: pure helpers: object paths, URL decoding, error statuses") {
    CHECK(*normalize_object_path("Webcams[0]") == "Webcams[0]");
    CHECK(*normalize_object_path("child_by_int[-1]") == "child_by_int[%2d1]");
    CHECK(*normalize_object_path("child_by_int[%2d1]") == "child_by_int[%2d1]");
    CHECK(*normalize_object_path("child_by_name[with space_and-dash].leaf") ==
          "child_by_name[with%20space%5fand%2ddash].leaf");
    for (const char* bad : {"", ".a", "a.", "a..b", "a[", "a[]", "a]b", "a b"}) {
        INFO(bad);
        CHECK_FALSE(normalize_object_path(bad));
    }
    CHECK(*url_decode("a%5B0%5D+b", true) == "a[0] b");
    CHECK(*url_decode("a+b", false) == "a+b");
    CHECK_FALSE(url_decode("%4", false));
    CHECK_FALSE(url_decode("%zz", false));

    CHECK(device_error(make_error(MessageErrorType::RequestTimeout, "t")).status == 504);
    CHECK(device_error(make_error(MessageErrorType::ConnectionError, "c")).status == 503);
    CHECK(device_error(make_error(MessageErrorType::ObjectNotFound, "o")).status == 404);
    CHECK(device_error(make_error(MessageErrorType::MemberNotFound, "m")).status == 404);
    CHECK(device_error(make_error(MessageErrorType::ReadOnlyMember, "r")).status == 405);
    CHECK(device_error(make_error(MessageErrorType::WriteOnlyMember, "w")).status == 405);
    CHECK(device_error(make_error(MessageErrorType::InvalidArgument, "i")).status == 502);
    RRError user{MessageErrorType::RemoteError, "experimental.x.Fault", "f", ""};
    CHECK(device_error(user).status == 502);
    CHECK(device_error(user).name == "experimental.x.Fault");

    CHECK_FALSE(parse_request_json("{\"a\": "));
    CHECK_FALSE(parse_request_json(std::string(200, '[') + std::string(200, ']')));
    CHECK(parse_request_json("{\"s\": \"[[[[\"}"));
    // Invalid UTF-8 in a device's message never throws on the way out.
    CHECK(json_text(json{{"m", std::string("bad \xff byte")}}).find("bad") != std::string::npos);
}

TEST_CASE("json api: devices, definitions, the member summary") {
    RR_SKIP_WITHOUT_INTEROP_SERVICE();
    InteropProcess device;
    TestGateway gw(device.url());

    auto list = http_get(gw.port(), "/api/devices");
    REQUIRE(list.status == 200);
    CHECK(list.raw[bhttp::field::content_type] == "application/json");
    REQUIRE(list.body.is_array());
    REQUIRE(list.body.size() == 1);
    const auto& d = list.body[0];
    CHECK(d["name"] == "interop");
    CHECK(d["url"] == device.url());
    CHECK(d["state"] == "connected");
    CHECK(d["reason"].is_null());
    CHECK(d["object_type"] == "experimental.interop_test.Root");
    CHECK(d["required"] == true);
    CHECK(d["clients"].is_number_unsigned());
    CHECK(d["auth"] == "shared");
    CHECK(d["locks"] == json::array());  // held at the gateway: none yet
    CHECK_FALSE(d.contains("passthrough_sessions"));
    CHECK(http_get(gw.port(), "/api/devices/").body == list.body);

    auto info = http_get(gw.port(), "/api/devices/interop");
    REQUIRE(info.status == 200);
    CHECK(info.body["state"] == "connected");
    REQUIRE(info.body["definitions"].size() >= 1);
    CHECK(info.body["definitions"][0].get<std::string>().find("service experimental.interop_test") != std::string::npos);
    std::map<std::string, json> members;
    for (const auto& m : info.body["members"]) members[m["name"].get<std::string>()] = m;
    CHECK(members.at("p_double") == json{{"name", "p_double"}, {"kind", "property"}, {"type", "double"},
                                         {"modifiers", json::array()}, {"parameters", json::array()}});
    CHECK(members.at("ro_value")["modifiers"] == json{"readonly"});
    CHECK(members.at("add")["kind"] == "function");
    CHECK(members.at("add")["type"] == "int32");
    CHECK(members.at("add")["parameters"] == json{{{"name", "a"}, {"type", "int32"}}, {{"name", "b"}, {"type", "int32"}}});
    CHECK(members.at("count_up")["type"] == "int32{generator}");
    CHECK(members.at("ev_values")["kind"] == "event");
    CHECK(members.at("ev_values")["type"].is_null());
    CHECK(members.at("ev_values")["parameters"].size() == 3);
    CHECK(members.at("w_state")["kind"] == "wire");
    CHECK(members.at("p_unreliable")["modifiers"] == json{"unreliable"});
    CHECK(members.at("child_by_int")["type"] == "Child{int32}");
    CHECK(members.at("mem_md")["kind"] == "memory");

    auto defs = http_get(gw.port(), "/api/devices/interop/definitions");
    REQUIRE(defs.status == 200);
    CHECK(defs.body["definitions"] == info.body["definitions"]);

    auto missing = http_get(gw.port(), "/api/devices/nosuch");
    CHECK(missing.status == 404);
    CHECK(error_name_of(missing) == "RobotRaconteur.ServiceNotFound");
    CHECK(http_get(gw.port(), "/api/devices/nosuch/definitions").status == 404);
    CHECK(http_get(gw.port(), "/api/devices/nosuch/properties/x").status == 404);
    auto route = http_get(gw.port(), "/api/devices/interop/nothing/p_int32");
    CHECK(route.status == 404);
    CHECK(error_name_of(route) == "RobotRaconteur.ResourceNotFound");
    CHECK(http_get(gw.port(), "/api/devicesX").status == 404);
    auto method = http_request(gw.port(), bhttp::verb::post, "/api/devices");
    CHECK(method.status == 405);
    CHECK(method.raw[bhttp::field::allow] == "GET");

    // Issue 15: methods no route takes and paths under /api that are no route answer in JSON too.
    auto is_json_error = [](const HttpReply& r, const char* name) {
        INFO(r.raw.body());
        CHECK(r.raw[bhttp::field::content_type] == "application/json");
        REQUIRE(r.body.is_object());
        CHECK(error_name_of(r) == name);
        CHECK(r.body["error"]["message"].is_string());
    };
    struct MethodCase {
        bhttp::verb verb;
        std::string target;
        const char* allow;
    };
    for (const auto& c : {MethodCase{bhttp::verb::delete_, "/api/devices/interop/properties/p_int32", "GET, PUT"},
                          MethodCase{bhttp::verb::patch, "/api/devices/interop", "GET"},
                          MethodCase{bhttp::verb::delete_, "/api/devices", "GET"},
                          MethodCase{bhttp::verb::patch, "/api/devices/interop/functions/add", "POST"},
                          MethodCase{bhttp::verb::put, "/api/devices/interop/wires/w_state", "GET"},
                          MethodCase{bhttp::verb::delete_, "/api/discovered", "GET"},
                          MethodCase{bhttp::verb::get, "/api/discovered/add", "POST"}}) {
        INFO(c.target);
        auto r = http_request(gw.port(), c.verb, c.target);
        CHECK(r.status == 405);
        CHECK(r.raw[bhttp::field::allow] == c.allow);
        is_json_error(r, "RobotRaconteur.InvalidOperation");
    }
    for (const char* target : {"/api", "/api/", "/api/nothing", "/api/v2/devices", "/api/devicesX"}) {
        INFO(target);
        auto r = http_get(gw.port(), target);
        CHECK(r.status == 404);
        is_json_error(r, "RobotRaconteur.ResourceNotFound");
        CHECK(http_request(gw.port(), bhttp::verb::delete_, target).status == 404);
    }
    // Outside /api the server's own answers stay as they were (pages, probes).
    auto page = http_get(gw.port(), "/no-such-page");
    CHECK(page.status == 404);
    CHECK(page.raw[bhttp::field::content_type] != "application/json");
}

TEST_CASE("json api: every read/write property round-trips through JSON unchanged") {
    RR_SKIP_WITHOUT_INTEROP_SERVICE();
    InteropProcess device;
    TestGateway gw(device.url());
    auto info = http_get(gw.port(), "/api/devices/interop");
    REQUIRE(info.status == 200);
    int checked = 0;
    for (const auto& m : info.body["members"]) {
        if (m["kind"] != "property" || !m["modifiers"].empty()) continue;
        if (m["name"].get<std::string>().rfind("wo", 0) == 0) continue;
        const std::string name = m["name"];
        INFO(name << " (" << m["type"].get<std::string>() << ")");
        auto got = http_get(gw.port(), kProps + name);
        REQUIRE(got.status == 200);
        REQUIRE(got.body.contains("value"));
        // The service accepts only its value A (or B): JSON -> value -> wire must give A back exactly.
        auto put = http_put(gw.port(), kProps + name, json{{"value", got.body["value"]}});
        INFO(put.raw.body());
        CHECK(put.status == 200);
        CHECK(put.body == json::object());
        ++checked;
    }
    CHECK(checked >= 60);

    // Known values (interop_values.py).
    CHECK(http_get(gw.port(), kProps + "p_int32").body == json{{"value", -2147483648}});
    CHECK(http_get(gw.port(), kProps + "p_uint64").body == json{{"value", "18446744073709551615"}});
    CHECK(http_get(gw.port(), kProps + "p_enum").body == json{{"value", 16}});
    CHECK(http_get(gw.port(), kProps + "s_null").body == json{{"value", nullptr}});
    CHECK(http_get(gw.port(), kProps + "m_fixed").body ==
          json{{"value", {{"dims", {2, 3}}, {"array", {-1, 2, -3, 4, -5, 6}}}}});
    CHECK(http_get(gw.port(), kProps + "na_scalar").body ==
          json{{"value", {{"x", 0.5}, {"y", 0.0}, {"z", 1e-300}}}});
    CHECK(http_get(gw.port(), kProps + "v_any").body["value"]["type"] == "experimental.interop_test.Inner");

    // B is accepted, anything else is refused by the device (502 with its error name).
    CHECK(http_put(gw.port(), kProps + "p_int32", json{{"value", 2147483647}}).status == 200);
    CHECK(http_get(gw.port(), kProps + "p_int32").body == json{{"value", 2147483647}});
    CHECK(http_put(gw.port(), kProps + "p_enum", json{{"value", "minus"}}).status == 200);
    CHECK(http_get(gw.port(), kProps + "p_enum").body == json{{"value", -5}});
    auto refused = http_put(gw.port(), kProps + "p_int32", json{{"value", 5}});
    CHECK(refused.status == 502);
    CHECK(error_name_of(refused) == "RobotRaconteur.InvalidArgument");

    // Values that do not fit the type: 400 with the JSON mapping's error.
    auto mismatch = http_put(gw.port(), kProps + "p_int32", json{{"value", "abc"}});
    CHECK(mismatch.status == 400);
    CHECK(error_name_of(mismatch) == "RobotRaconteur.DataTypeMismatch");
    CHECK(error_name_of(http_put(gw.port(), kProps + "p_int8", json{{"value", 200}})) == "RobotRaconteur.OutOfRange");
    CHECK(error_name_of(http_put(gw.port(), kProps + "a_fixed", json{{"value", {1.0}}})) == "RobotRaconteur.DataTypeError");
    CHECK(error_name_of(http_put(gw.port(), kProps + "p_double", json{{"value", nullptr}})) == "RobotRaconteur.NullValue");
    CHECK(error_name_of(http_put(gw.port(), kProps + "p_enum", json{{"value", "purple"}})) == "RobotRaconteur.InvalidArgument");
    CHECK(error_name_of(http_put(gw.port(), kProps + "s_inner", json{{"value", {{"id", 1}}}})) == "RobotRaconteur.DataTypeError");
    auto not_json = http_request(gw.port(), bhttp::verb::put, kProps + "p_int32", "{\"value\": ");
    CHECK(not_json.status == 400);
    CHECK(error_name_of(not_json) == "RobotRaconteur.InvalidArgument");
    CHECK(http_put(gw.port(), kProps + "p_int32", json{{"val", 1}}).status == 400);
    CHECK(http_put(gw.port(), kProps + "p_int32", json::array({1})).status == 400);
    auto deep = http_request(gw.port(), bhttp::verb::put, kProps + "v_any",
                             "{\"value\": " + std::string(5000, '[') + std::string(5000, ']') + "}");
    CHECK(deep.status == 400);
    auto huge = http_request(gw.port(), bhttp::verb::put, kProps + "p_string",
                             "{\"value\": \"" + std::string((1u << 20) + 1024, 'x') + "\"}");
    CHECK(huge.status == 413);  // over HttpOptions::max_body_bytes, refused by the HttpServer

    // Modifiers and kinds.
    CHECK(http_get(gw.port(), kProps + "ro_value").body == json{{"value", 17}});
    auto ro = http_put(gw.port(), kProps + "ro_value", json{{"value", 1}});
    CHECK(ro.status == 405);
    CHECK(error_name_of(ro) == "RobotRaconteur.ReadOnlyMember");
    auto wo = http_get(gw.port(), kProps + "wo_value");
    CHECK(wo.status == 405);
    CHECK(error_name_of(wo) == "RobotRaconteur.WriteOnlyMember");
    CHECK(http_put(gw.port(), kProps + "wo_value", json{{"value", 9}}).status == 200);
    CHECK(call(gw.port(), "wo_value_last", json::object()) == json{{"return", 9}});
    auto kind = http_get(gw.port(), kProps + "add");
    CHECK(kind.status == 404);
    CHECK(error_name_of(kind) == "RobotRaconteur.MemberNotFound");
    CHECK(http_get(gw.port(), kProps + "nosuch").status == 404);
    CHECK(http_request(gw.port(), bhttp::verb::post, kProps + "p_int32", "{}").status == 405);
}

TEST_CASE("json api: objects below the root are addressed with ?object=") {
    RR_SKIP_WITHOUT_INTEROP_SERVICE();
    InteropProcess device;
    TestGateway gw(device.url());
    CHECK(http_get(gw.port(), kProps + "value?object=child").body == json{{"value", 1}});
    CHECK(http_get(gw.port(), kProps + "name?object=child").body == json{{"value", "child[plain]"}});
    CHECK(http_get(gw.port(), kProps + "value?object=child_by_int%5B-1%5D").body == json{{"value", 99}});
    CHECK(http_get(gw.port(), kProps + "value?object=child_by_int[%252d1]").body == json{{"value", 99}});
    CHECK(http_get(gw.port(), kProps + "value?object=child_by_int[7]").body == json{{"value", 107}});
    CHECK(http_get(gw.port(), kProps + "value?object=child_by_name[with+space_and-dash]").body == json{{"value", 201}});
    CHECK(http_get(gw.port(), kProps + "x?object=child.leaf").body == json{{"value", 1.5}});
    CHECK(http_get(gw.port(), kProps + "x?object=any_obj").body == json{{"value", -3.5}});
    CHECK(http_put(gw.port(), kProps + "value?object=child_by_int[0]", json{{"value", 5}}).status == 200);
    CHECK(http_get(gw.port(), kProps + "value?object=child_by_int[0]").body == json{{"value", 5}});
    CHECK(call(gw.port(), "describe?object=child_by_int[0]", json::object()) == json{{"return", "child[0] value=5"}});
    CHECK(call(gw.port(), "scaled?object=child.leaf", json{{"args", {2.0}}}) == json{{"return", 3.0}});

    auto unknown = http_get(gw.port(), kProps + "value?object=child_by_int[5]");
    CHECK(unknown.status == 404);
    CHECK(error_name_of(unknown) == "RobotRaconteur.ObjectNotFound");
    CHECK(http_get(gw.port(), kProps + "value?object=nosuch").status == 404);
    CHECK(http_get(gw.port(), kProps + "nosuch?object=child").status == 404);
    auto bad = http_get(gw.port(), kProps + "value?object=child..leaf");
    CHECK(bad.status == 400);
    CHECK(error_name_of(bad) == "RobotRaconteur.InvalidArgument");
    CHECK(http_get(gw.port(), kProps + "value?object=%zz").status == 400);
}

TEST_CASE("json api: functions, device errors, generators") {
    RR_SKIP_WITHOUT_INTEROP_SERVICE();
    InteropProcess device;
    TestGateway gw(device.url());
    const auto port = gw.port();
    CHECK(call(port, "add", json{{"args", {1, 2}}}) == json{{"return", 3}});
    CHECK(call(port, "add", json{{"args", {{"b", 2}, {"a", 40}}}}) == json{{"return", 42}});
    CHECK(call(port, "reset", json::object()) == json{{"return", nullptr}});
    CHECK(http_request(port, bhttp::verb::post, kFuncs + "reset").status == 200);  // no body at all
    CHECK(call(port, "make_inner", json{{"args", {3, "x", {1.5}}}}) ==
          json{{"return", {{"id", 3}, {"label", "x"}, {"values", {1.5}}}}});
    CHECK(call(port, "echo", json{{"args", {{{"type", "string"}, {"value", "hi"}}}}}) ==
          json{{"return", {{"type", "string"}, {"value", "hi"}}}});
    CHECK(call(port, "catalog", json{{"args", {"int32[*]"}}})["return"] ==
          json{{"type", "int32[*]"}, {"value", {{"dims", {2, 2, 2}}, {"array", {0, 1, 2, 3, 4, 5, 6, 7}}}}});

    for (const auto& [body, name] : std::vector<std::pair<json, std::string>>{
             {json{{"args", {1}}}, "RobotRaconteur.InvalidArgument"},
             {json{{"args", {{"a", 1}}}}, "RobotRaconteur.InvalidArgument"},
             {json{{"args", {{"a", 1}, {"b", 2}, {"c", 3}}}}, "RobotRaconteur.InvalidArgument"},
             {json{{"args", {"x", 1}}}, "RobotRaconteur.DataTypeMismatch"},
             {json{{"args", 5}}, "RobotRaconteur.InvalidArgument"},
             {json{{"arguments", {1, 2}}}, "RobotRaconteur.InvalidArgument"},
             {json{{"args", {1, 2}}, {"max_items", -1}}, "RobotRaconteur.InvalidArgument"}}) {
        INFO(body.dump());
        auto r = http_post(port, kFuncs + "add", body);
        CHECK(r.status == 400);
        CHECK(error_name_of(r) == name);
    }
    auto overflow = http_post(port, kFuncs + "add", json{{"args", {2147483647, 1}}});
    CHECK(overflow.status == 502);
    CHECK(error_name_of(overflow) == "RobotRaconteur.OutOfRange");
    auto user = http_post(port, kFuncs + "throw_user", json{{"args", {"boom"}}});
    CHECK(user.status == 502);
    CHECK(error_name_of(user) == "experimental.interop_test.InteropError");
    CHECK(user.body["error"]["message"] == "boom");
    auto standard = http_post(port, kFuncs + "throw_standard", json::object());
    CHECK(standard.status == 502);
    CHECK(error_name_of(standard) == "RobotRaconteur.InvalidArgument");
    CHECK(http_post(port, kFuncs + "p_int32", json::object()).status == 404);
    CHECK(http_post(port, kFuncs + "nosuch", json::object()).status == 404);
    CHECK(http_get(port, kFuncs + "add").status == 405);

    // Generators: collected into items, then closed.
    CHECK(call(port, "count_up", json{{"args", {5, 3}}}) == json{{"items", {5, 6, 7}}});
    CHECK(call(port, "count_up", json{{"args", {0, 1000}}, {"max_items", 4}}) == json{{"items", {0, 1, 2, 3}}});
    CHECK(call(port, "count_up?max_items=2", json{{"args", {10, 1000}}}) == json{{"items", {10, 11}}});
    CHECK(call(port, "count_up", json{{"args", {0, 1000}}})["items"].size() == 100);  // the default max_items
    CHECK(http_post(port, kFuncs + "count_up?max_items=x", json{{"args", {0, 1}}}).status == 400);
    CHECK(http_post(port, kFuncs + "count_up", json{{"args", {0, 1}}, {"max_items", 1000000}}).status == 400);
    CHECK(call(port, "running_sum", json{{"args", {{1.0, 2.0, 3.5}}}}) == json{{"items", {1.0, 3.0, 6.5}}});
    CHECK(call(port, "running_sum", json{{"args", {{"values", json::array()}}}}) == json{{"items", json::array()}});
    CHECK(call(port, "collect", json{{"args", json::array({json::array({"a", "b"})})}}) == json{{"items", json::array()}});
    CHECK(http_get(port, kProps + "collected").body == json{{"value", {"a", "b"}}});
    auto bad_items = http_post(port, kFuncs + "running_sum", json{{"args", {{1.0, "x"}}}});
    CHECK(bad_items.status == 400);
    CHECK(error_name_of(bad_items) == "RobotRaconteur.DataTypeMismatch");
    CHECK(http_post(port, kFuncs + "running_sum", json{{"args", {1.0}}}).status == 400);
    auto log = call(port, "generator_log", json::object())["return"];
    INFO(log.dump());
    // count_up(0, 1000) with max_items 4 and 2 and 100 ended early: closed by the gateway.
    CHECK(std::count(log.begin(), log.end(), json("count_up:close")) == 3);
    CHECK(std::count(log.begin(), log.end(), json("running_sum:close")) == 2);
    CHECK(std::count(log.begin(), log.end(), json("collect:close")) == 1);
}

TEST_CASE("json api: wires are peeked, the Origin policy holds on API routes") {
    RR_SKIP_WITHOUT_INTEROP_SERVICE();
    InteropProcess device;
    TestGateway gw(device.url());
    const auto port = gw.port();
    auto state = http_get(port, "/api/devices/interop/wires/w_state");
    REQUIRE(state.status == 200);
    CHECK(state.body["value"]["id"].is_number_integer());
    CHECK(state.body["value"]["values"].is_array());
    CHECK(state.body["time"]["seconds"].get<std::int64_t>() > 1600000000);
    CHECK(state.body["time"]["nanoseconds"].get<std::int64_t>() < 1000000000);
    CHECK(http_get(port, "/api/devices/interop/wires/w_both").body["value"] == json{0.0});
    auto sink = http_get(port, "/api/devices/interop/wires/w_sink");
    CHECK(sink.status == 405);
    CHECK(error_name_of(sink) == "RobotRaconteur.WriteOnlyMember");
    CHECK(http_get(port, "/api/devices/interop/wires/p_int32").status == 404);

    auto forbidden = http_request(port, bhttp::verb::get, "/api/devices", {}, "http://evil.test");
    CHECK(forbidden.status == 403);
    auto allowed = http_request(port, bhttp::verb::get, "/api/devices", {}, "http://allowed.test");
    CHECK(allowed.status == 200);
    CHECK(allowed.raw[bhttp::field::access_control_allow_origin] == "http://allowed.test");
    auto preflight = http_request(port, bhttp::verb::options, kProps + "p_int32", {}, "http://allowed.test");
    CHECK(preflight.status == 204);
    CHECK(preflight.raw[bhttp::field::access_control_allow_methods] == "GET, PUT, POST");
}

TEST_CASE("json api: a device that is not connected gives 503") {
    RR_SKIP_WITHOUT_INTEROP_SERVICE();
    auto device = std::make_unique<InteropProcess>();
    TestGateway gw(device->url());
    CHECK(http_get(gw.port(), kProps + "p_int32").status == 200);
    const auto url = device->url();
    device->stop();
    REQUIRE(gw.wait_state(DeviceState::failed));
    auto r = http_get(gw.port(), kProps + "p_int32");
    CHECK(r.status == 503);
    CHECK(error_name_of(r) == "RobotRaconteur.ConnectionError");
    CHECK(http_post(gw.port(), kFuncs + "add", json{{"args", {1, 2}}}).status == 503);
    auto list = http_get(gw.port(), "/api/devices");
    CHECK(list.body[0]["state"] != "connected");
    CHECK(list.body[0]["reason"].is_string());
}

TEST_CASE("json api: the installer of rr-gateway serves the same API") {
    RR_SKIP_WITHOUT_INTEROP_SERVICE();
    InteropProcess device;
    app::GatewayConfig cfg;
    cfg.local = false;  // tests run side by side: no shared NodeName on this computer
    cfg.port = 0;
    cfg.listen = "127.0.0.1";
    cfg.demo = false;
    DeviceConfig d;
    d.name = "interop";
    d.url = device.url();
    cfg.devices.push_back(d);
    auto g = app::Gateway::start(cfg, {}, install_json_api);
    REQUIRE(g);
    REQUIRE(rr::testing::eventually([&] { return (*g)->ready(); }));
    CHECK(http_get((*g)->port(), kProps + "ro_value").body == json{{"value", 17}});
    WsClient ws((*g)->port());
    CHECK(ws.handshake_response()[bhttp::field::sec_websocket_protocol] == kJsonSubprotocol);
    auto reply = ws.request(json{{"op", "get"}, {"device", "interop"}, {"member", "ro_value"}});
    CHECK(reply["result"] == json{{"value", 17}});
    ws.close();
    // Issue 40: what the gateway serves of its optional parts, asked once by the dashboard.
    auto features = http_get((*g)->port(), "/api/features");
    CHECK(features.status == 200);
    CHECK(features.body == json{{"discovery", true}, {"auth", false}});  // discovery is on by default
    CHECK(http_get((*g)->port(), "/api/whoami").body == json{{"auth", false}});  // served without logins too
    CHECK(http_request((*g)->port(), bhttp::verb::post, "/api/features").status == 405);
    (*g)->stop();
    cfg.discovery.enabled = false;
    auto quiet = app::Gateway::start(cfg, {}, install_json_api);
    REQUIRE(quiet);
    CHECK(http_get((*quiet)->port(), "/api/features").body == json{{"discovery", false}, {"auth", false}});
    CHECK(http_get((*quiet)->port(), "/api/discovered").status == 404);
    (*quiet)->stop();
}
