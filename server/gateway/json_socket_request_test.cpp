// The JSON WebSocket's requests (json_socket_request.hpp): envelopes refused with the id to answer
// under, and each op's fields checked before anything is looked up.
#include <catch2/catch.hpp>

#include <algorithm>

#include "server/gateway/json_socket_request.hpp"

using namespace rr;
using namespace rr::server::gateway;
using nlohmann::json;

namespace {

SocketEnvelope envelope(const json& message) {
    auto parsed = parse_socket_envelope(message.dump(), 1u << 20);
    REQUIRE(std::holds_alternative<SocketEnvelope>(parsed));
    return std::get<SocketEnvelope>(std::move(parsed));
}

SocketRejection refused(std::string_view text, std::size_t max_bytes = 1u << 20) {
    auto parsed = parse_socket_envelope(text, max_bytes);
    REQUIRE(std::holds_alternative<SocketRejection>(parsed));
    return std::get<SocketRejection>(std::move(parsed));
}

SocketRequest request(const json& message, bool with_logins = false) {
    auto parsed = parse_socket_request(envelope(message), with_logins);
    if (auto* e = std::get_if<ApiError>(&parsed)) FAIL("refused: " << e->message);
    return std::get<SocketRequest>(std::move(parsed));
}

ApiError error(const json& message, bool with_logins = false) {
    auto parsed = parse_socket_request(envelope(message), with_logins);
    REQUIRE(std::holds_alternative<ApiError>(parsed));
    return std::get<ApiError>(std::move(parsed));
}

}  // namespace

TEST_CASE("socket request: envelopes that are refused, and the id each is answered under") {
    auto over = refused(R"({"id": 1, "op": "devices"})", 10);
    CHECK(over.id.is_null());
    CHECK(over.error.name == "RobotRaconteur.BufferLimitViolation");
    CHECK(over.error.message == "message of 26 bytes is over the limit of 10");

    CHECK(refused("{not json").error.name == "RobotRaconteur.InvalidArgument");
    CHECK(refused(R"([1, 2])").error.message == "a request is a JSON object");
    CHECK(refused(R"({"op": "devices"})").error.message == "a request needs an \"id\" (integer or string)");
    CHECK(refused(R"({"id": 1.5, "op": "devices"})").error.message == "a request needs an \"id\" (integer or string)");
    CHECK(refused(R"({"id": true, "op": "devices"})").id.is_null());

    auto no_op = refused(R"({"id": "a7"})");
    CHECK(no_op.id == "a7");  // the op is missing, the id is usable: answered under it
    CHECK(no_op.error.message == "a request needs an \"op\" (string)");
    CHECK(refused(R"({"id": 3, "op": 4})").id == 3);

    std::string deep(200, '[');
    CHECK(refused(R"({"id": 1, "op": "set", "value": )" + deep).error.status == 400);
}

TEST_CASE("socket request: an envelope keeps the id, the op and the whole message") {
    auto e = envelope(json{{"id", 7}, {"op", "devices"}, {"extra", true}});
    CHECK(e.id == 7);
    CHECK(e.op == "devices");
    CHECK(e.message.at("extra") == true);
}

TEST_CASE("socket request: the op table") {
    auto ops = socket_ops();
    REQUIRE(ops.size() == 14);
    CHECK(ops.front() == "login");
    for (auto name : {"device_login", "device_logout", "devices", "device", "access", "get", "set", "call", "peek", "subscribe",
                      "unsubscribe", "set_out_value", "send"})
        CHECK(std::find(ops.begin(), ops.end(), std::string_view(name)) != ops.end());
    // Every op in the table is known: a message without its fields is refused for a field, not the op.
    for (auto name : ops) {
        auto parsed = parse_socket_request(envelope(json{{"id", 1}, {"op", name}}), true);
        if (auto* e = std::get_if<ApiError>(&parsed)) CHECK(e->message.find("unknown op") == std::string::npos);
    }
    CHECK(error(json{{"id", 24}, {"op", "launch"}}).message == "unknown op \"launch\"");
}

TEST_CASE("socket request: login is an op only on a gateway with users") {
    const json by_password{{"id", 1}, {"op", "login"}, {"username", "ann"}, {"password", "pw"}};
    CHECK(error(by_password, false).message == "unknown op \"login\"");
    auto r = std::get<LoginRequest>(request(by_password, true));
    CHECK_FALSE(r.by_token);
    CHECK(r.username == "ann");
    CHECK(r.password == "pw");

    auto t = std::get<LoginRequest>(request(json{{"id", 1}, {"op", "login"}, {"token", "abc"}}, true));
    CHECK(t.by_token);
    CHECK(t.token == "abc");

    CHECK(error(json{{"id", 1}, {"op", "login"}, {"username", "ann"}}, true).message ==
          "login takes \"username\" and \"password\", or \"token\"");
    CHECK(error(json{{"id", 1}, {"op", "login"}, {"token", 5}}, true).status == 400);
}

TEST_CASE("socket request: device_login, device_logout, devices, device") {
    auto d = std::get<DeviceLoginRequest>(request(json{{"id", 1}, {"op", "device_login"}, {"device", "arm"}, {"username", "u"}}));
    CHECK(d.device == "arm");
    CHECK(d.username == "u");
    CHECK(d.password.empty());  // a device user without a password
    const std::string usage = "device_login takes \"device\", \"username\" (non-empty strings) and \"password\" (string)";
    CHECK(error(json{{"id", 1}, {"op", "device_login"}, {"device", "arm"}, {"username", ""}}).message == usage);
    CHECK(error(json{{"id", 1}, {"op", "device_login"}, {"device", "arm"}, {"username", "u"}, {"password", 1}}).message == usage);

    CHECK(std::get<DeviceLogoutRequest>(request(json{{"id", 1}, {"op", "device_logout"}, {"device", "arm"}})).device == "arm");
    CHECK(error(json{{"id", 1}, {"op", "device_logout"}}).message == "\"device\" (string) is required");
    CHECK(std::holds_alternative<DevicesRequest>(request(json{{"id", 1}, {"op", "devices"}})));
    CHECK(std::get<DeviceRequest>(request(json{{"id", 1}, {"op", "device"}, {"device", "cam"}})).device == "cam");
    CHECK(error(json{{"id", 1}, {"op", "device"}, {"device", 3}}).message == "\"device\" (string) is required");
}

TEST_CASE("socket request: access") {
    auto all = std::get<AccessRequest>(request(json{{"id", 1}, {"op", "access"}, {"device", "arm"}}));
    CHECK(all.device == "arm");
    CHECK_FALSE(all.members);
    CHECK_FALSE(all.device_user);
    auto some = std::get<AccessRequest>(
        request(json{{"id", 1}, {"op", "access"}, {"device", "arm"}, {"members", {"jog", "halt"}}, {"device_user", "ann"}}));
    CHECK(some.members == std::optional<std::string>("jog,halt"));
    CHECK(some.device_user == std::optional<std::string>("ann"));
    // Empty names stay visible as empty entries (member_access refuses them).
    CHECK(std::get<AccessRequest>(request(json{{"id", 1}, {"op", "access"}, {"device", "a"}, {"members", json::array()}})).members ==
          std::optional<std::string>(""));
    CHECK(std::get<AccessRequest>(request(json{{"id", 1}, {"op", "access"}, {"device", "a"}, {"members", {"", "x"}}})).members ==
          std::optional<std::string>(",x"));
    CHECK(error(json{{"id", 1}, {"op", "access"}}).message == "\"device\" (string) is required");
    CHECK(error(json{{"id", 1}, {"op", "access"}, {"device", "a"}, {"members", "jog"}}).message ==
          "\"members\" must be an array of member names");
    CHECK(error(json{{"id", 1}, {"op", "access"}, {"device", "a"}, {"members", {1}}}).status == 400);
    CHECK(error(json{{"id", 1}, {"op", "access"}, {"device", "a"}, {"device_user", 5}}).message == "\"device_user\" must be a string");
}

TEST_CASE("socket request: member operations") {
    auto get = std::get<MemberRequest>(request(json{{"id", 1}, {"op", "get"}, {"device", "arm"}, {"member", "speed"}}));
    CHECK(get.op == MemberOp::get);
    CHECK(get.address.device == "arm");
    CHECK(get.address.member == "speed");
    CHECK(get.address.object.empty());
    CHECK(get.address.device_session == 0);

    auto below = std::get<MemberRequest>(
        request(json{{"id", 1}, {"op", "peek"}, {"device", "arm"}, {"object", "tools[0]"}, {"member", "pos"}}));
    CHECK(below.op == MemberOp::peek);
    CHECK(below.address.object == "tools[0]");
    CHECK(std::get<MemberRequest>(request(json{{"id", 1}, {"op", "get"}, {"device", "a"}, {"object", nullptr}, {"member", "m"}}))
              .address.object.empty());
    CHECK(error(json{{"id", 1}, {"op", "get"}, {"device", "a"}, {"object", 3}, {"member", "m"}}).message ==
          "\"object\" must be a string (a relative service path)");
    CHECK(error(json{{"id", 1}, {"op", "get"}, {"device", "a"}}).message == "\"device\" and \"member\" (strings) are required");

    auto set = std::get<MemberRequest>(request(json{{"id", 1}, {"op", "set"}, {"device", "a"}, {"member", "m"}, {"value", {1, 2}}}));
    CHECK(set.value == json{1, 2});
    CHECK(error(json{{"id", 1}, {"op", "set"}, {"device", "a"}, {"member", "m"}}).message == "\"value\" is required");

    auto call = std::get<MemberRequest>(
        request(json{{"id", 1}, {"op", "call"}, {"device", "a"}, {"member", "f"}, {"args", {{"x", 1}}}, {"max_items", 5}}));
    CHECK(call.args == json{{"x", 1}});
    CHECK(call.max_items == 5);
    CHECK(std::get<MemberRequest>(request(json{{"id", 1}, {"op", "call"}, {"device", "a"}, {"member", "f"}})).args.is_null());
    CHECK(error(json{{"id", 1}, {"op", "call"}, {"device", "a"}, {"member", "f"}, {"max_items", -1}}).message ==
          "\"max_items\" must be a non-negative integer");

    auto sub = std::get<MemberRequest>(
        request(json{{"id", 1}, {"op", "subscribe"}, {"device", "a"}, {"member", "w"}, {"binary", true}}));
    CHECK(sub.op == MemberOp::subscribe);
    CHECK(sub.binary);
    CHECK(error(json{{"id", 1}, {"op", "subscribe"}, {"device", "a"}, {"member", "w"}, {"binary", 1}}).message ==
          "\"binary\" must be true or false");
}

TEST_CASE("socket request: subscribe's max_rate_hz and queue_length, bad values refused") {
    auto sub = [](json more) {
        json j{{"id", 1}, {"op", "subscribe"}, {"device", "a"}, {"member", "p"}};
        j.update(more);
        return j;
    };
    auto plain = std::get<MemberRequest>(request(sub(json::object())));
    CHECK_FALSE(plain.max_rate_hz);
    CHECK(plain.rate_period == RateClock(0));
    CHECK_FALSE(plain.queue_length);

    auto limited = std::get<MemberRequest>(request(sub({{"max_rate_hz", 10}, {"queue_length", 5}})));
    CHECK(limited.max_rate_hz == 10.0);
    CHECK(limited.rate_period == std::chrono::milliseconds(100));
    CHECK(limited.queue_length == 5u);
    CHECK(std::get<MemberRequest>(request(sub({{"max_rate_hz", 2.5}}))).rate_period == std::chrono::milliseconds(400));

    const std::string range = "\"max_rate_hz\" must be a number from 0.01 to 1000";
    for (const json& bad : {json(0), json(-5), json(1000.5), json(1e300), json(0.001)}) {
        INFO(bad.dump());
        CHECK(error(sub({{"max_rate_hz", bad}})).message == range);
    }
    CHECK(error(sub({{"max_rate_hz", "10"}})).message == "\"max_rate_hz\" must be a number (values per second)");
    CHECK(error(sub({{"max_rate_hz", nullptr}})).message == "\"max_rate_hz\" must be a number (values per second)");
    const std::string length = "\"queue_length\" must be an integer from 1 to 64";
    for (const json& bad : {json(0), json(65), json(-1), json(2.5), json("3")}) {
        INFO(bad.dump());
        CHECK(error(sub({{"max_rate_hz", 1}, {"queue_length", bad}})).message == length);
    }
    CHECK(error(sub({{"queue_length", 3}})).message ==
          "\"queue_length\" needs \"max_rate_hz\" (a pipe's packets wait for their window)");
}

TEST_CASE("socket request: operations on a subscription") {
    CHECK(std::get<UnsubscribeRequest>(request(json{{"id", 1}, {"op", "unsubscribe"}, {"subscription", 4}})).subscription == 4);
    const std::string need_sid = "\"subscription\" (a subscription id) is required";
    CHECK(error(json{{"id", 1}, {"op", "unsubscribe"}}).message == need_sid);
    CHECK(error(json{{"id", 1}, {"op", "unsubscribe"}, {"subscription", -4}}).message == need_sid);
    CHECK(error(json{{"id", 1}, {"op", "unsubscribe"}, {"subscription", "4"}}).message == need_sid);

    auto out = std::get<SetOutValueRequest>(request(json{{"id", 1}, {"op", "set_out_value"}, {"subscription", 2}, {"value", 0.5}}));
    CHECK(out.subscription == 2);
    CHECK(out.value == 0.5);
    CHECK(error(json{{"id", 1}, {"op", "set_out_value"}, {"subscription", 2}}).message == "\"value\" is required");

    auto send = std::get<SendRequest>(
        request(json{{"id", 1}, {"op", "send"}, {"subscription", 3}, {"value", "x"}, {"requestack", true}}));
    CHECK(send.subscription == 3);
    CHECK(send.request_ack);
    CHECK_FALSE(std::get<SendRequest>(request(json{{"id", 1}, {"op", "send"}, {"subscription", 3}, {"value", "x"}})).request_ack);
    CHECK(error(json{{"id", 1}, {"op", "send"}, {"subscription", 3}, {"value", "x"}, {"requestack", "yes"}}).message ==
          "\"requestack\" must be true or false");
}
