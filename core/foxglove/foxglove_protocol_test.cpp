#include <catch2/catch.hpp>

#include "core/foxglove/foxglove_protocol.hpp"

using namespace rr;
using namespace rr::foxglove;
using nlohmann::json;

namespace {
std::string bytes(std::initializer_list<int> b) {
    std::string s;
    for (int x : b) s.push_back(static_cast<char>(x));
    return s;
}
}  // namespace

TEST_CASE("protocol: server messages carry the spec's field names") {
    ServerInfo info{"rr-gateway", {capability::parameters, capability::services}, {"json"}, {{"k", "v"}}, "s1"};
    auto j = json::parse(server_info_json(info));
    CHECK(j["op"] == "serverInfo");
    CHECK(j["name"] == "rr-gateway");
    CHECK(j["capabilities"] == json({"parameters", "services"}));
    CHECK(j["supportedEncodings"] == json({"json"}));
    CHECK(j["metadata"]["k"] == "v");
    CHECK(j["sessionId"] == "s1");

    j = json::parse(advertise_json({Channel{7, "create/packets", "json", "experimental.create.Create.packets", "{}", "jsonschema"}}));
    CHECK(j["op"] == "advertise");
    CHECK(j["channels"][0] == json({{"id", 7}, {"topic", "create/packets"}, {"encoding", "json"},
                                     {"schemaName", "experimental.create.Create.packets"}, {"schema", "{}"},
                                     {"schemaEncoding", "jsonschema"}}));
    CHECK(json::parse(unadvertise_json({1, 2})) == json({{"op", "unadvertise"}, {"channelIds", {1, 2}}}));
    CHECK(json::parse(status_json(StatusLevel::error, "bad")) == json({{"op", "status"}, {"level", 2}, {"message", "bad"}}));

    j = json::parse(parameter_values_json({Parameter{"create/DistanceTraveled", 12, ""}, Parameter{"x", nullptr, ""}}, "r1"));
    CHECK(j["op"] == "parameterValues");
    CHECK(j["id"] == "r1");
    CHECK(j["parameters"][0] == json({{"name", "create/DistanceTraveled"}, {"value", 12}}));
    CHECK_FALSE(j["parameters"][1].contains("value"));  // unset: no value
    CHECK_FALSE(json::parse(parameter_values_json({}, std::nullopt)).contains("id"));

    Service s{3, "create/Drive", "experimental.create.Create.Drive", {"json", "Drive request", "jsonschema", "{\"a\":1}"},
              {"json", "Drive response", "jsonschema", "{}"}};
    j = json::parse(advertise_services_json({s}))["services"][0];
    CHECK(j["id"] == 3);
    CHECK(j["request"]["schemaName"] == "Drive request");
    CHECK(j["response"]["encoding"] == "json");
    CHECK(j["request"]["schema"] == "{\"a\":1}");
    CHECK_FALSE(j.contains("requestSchema"));  // the deprecated form, which Lichtblick warns about
    CHECK(json::parse(service_call_failure_json(3, 9, "no")) ==
          json({{"op", "serviceCallFailure"}, {"serviceId", 3}, {"callId", 9}, {"message", "no"}}));
}

TEST_CASE("protocol: binary frames are little-endian with the spec's opcodes") {
    CHECK(message_data_head(0x01020304, 0x1122334455667788ull) ==
          bytes({1, 4, 3, 2, 1, 0x88, 0x77, 0x66, 0x55, 0x44, 0x33, 0x22, 0x11}));
    CHECK(time_frame(1) == bytes({2, 1, 0, 0, 0, 0, 0, 0, 0}));
    CHECK(service_call_response_head(5, 6, "json") == bytes({3, 5, 0, 0, 0, 6, 0, 0, 0, 4, 0, 0, 0}) + "json");
}

TEST_CASE("protocol: client text messages decode") {
    auto m = decode_text(R"({"op":"subscribe","subscriptions":[{"id":0,"channelId":3},{"id":1,"channelId":5}]})");
    REQUIRE(m);
    auto& sub = std::get<Subscribe>(*m);
    REQUIRE(sub.subscriptions.size() == 2);
    CHECK(sub.subscriptions[1].id == 1);
    CHECK(sub.subscriptions[1].channel_id == 5);

    m = decode_text(R"({"op":"unsubscribe","subscriptionIds":[0,4294967295]})");
    REQUIRE(m);
    CHECK(std::get<Unsubscribe>(*m).subscription_ids == std::vector<std::uint32_t>{0, 4294967295u});

    m = decode_text(R"({"op":"advertise","channels":[{"id":2,"topic":"create/packets","encoding":"json","schemaName":"P"}]})");
    REQUIRE(m);
    CHECK(std::get<ClientAdvertise>(*m).channels.at(0).topic == "create/packets");

    m = decode_text(R"({"op":"getParameters","parameterNames":["a","b"],"id":"q"})");
    REQUIRE(m);
    CHECK(std::get<GetParameters>(*m).names == std::vector<std::string>{"a", "b"});
    CHECK(std::get<GetParameters>(*m).id == std::optional<std::string>("q"));

    m = decode_text(R"({"op":"setParameters","parameters":[{"name":"a","value":[1.5,2],"type":"float64_array"}]})");
    REQUIRE(m);
    CHECK(std::get<SetParameters>(*m).parameters.at(0).value == json({1.5, 2}));
    CHECK_FALSE(std::get<SetParameters>(*m).id);

    m = decode_text(R"({"op":"subscribeParameterUpdates","parameterNames":[]})");
    REQUIRE(m);
    CHECK(std::get<SubscribeParameterUpdates>(*m).names.empty());
}

TEST_CASE("protocol: malformed client messages are refused with the reason") {
    auto why = [](std::string_view text) {
        auto m = decode_text(text, DecodeLimits{});
        return m ? std::string("accepted") : m.error().message;
    };
    CHECK(why("not json") == "the text message is not JSON");
    CHECK(why("[1]") == "the text message is not a JSON object");
    CHECK(why("{}") == "\"op\" is missing");
    CHECK(why(R"({"op":7})") == "\"op\" is not a string");
    CHECK(why(R"({"op":"fly"})") == "unknown op \"fly\"");
    CHECK(why(R"({"op":"subscribe"})") == "\"subscriptions\" is missing");
    CHECK(why(R"({"op":"subscribe","subscriptions":{}})") == "\"subscriptions\" is not an array");
    CHECK(why(R"({"op":"subscribe","subscriptions":[{"id":-1,"channelId":1}]})") == "\"id\" is not a non-negative integer");
    CHECK(why(R"({"op":"subscribe","subscriptions":[{"id":1.5,"channelId":1}]})") == "\"id\" is not a non-negative integer");
    CHECK(why(R"({"op":"subscribe","subscriptions":[{"id":4294967296,"channelId":1}]})") == "\"id\" is over 2^32-1");
    CHECK(why(R"({"op":"subscribe","subscriptions":[3]})") == "\"subscriptions\" holds a value that is not an object");
    CHECK(why(R"({"op":"unsubscribe","subscriptionIds":["a"]})") ==
          "\"subscriptionIds\" holds a value that is not an id (0 to 2^32-1)");
    CHECK(why(R"({"op":"advertise","channels":[{"id":1,"encoding":"json"}]})") == "\"topic\" is missing");
    CHECK(why(R"({"op":"setParameters","parameters":[{"name":"a","type":"int"}]})") ==
          "parameter type \"int\" is not byte_array, float64 or float64_array");
    CHECK(why(R"({"op":"getParameters","parameterNames":[1]})") == "\"parameterNames\" holds a value that is not a string");

    DecodeLimits small;
    small.max_items = 2;
    small.max_text_bytes = 200;
    auto m = decode_text(R"({"op":"unsubscribe","subscriptionIds":[1,2,3]})", small);
    REQUIRE_FALSE(m);
    CHECK(m.error().type == MessageErrorType::BufferLimitViolation);
    m = decode_text(std::string(201, ' '), small);
    REQUIRE_FALSE(m);
    CHECK(m.error().type == MessageErrorType::BufferLimitViolation);
    m = decode_text(std::string(100000, '[') , DecodeLimits{});  // refused before parsing (no deep recursion)
    REQUIRE_FALSE(m);
    CHECK(m.error().type == MessageErrorType::BufferLimitViolation);
}

TEST_CASE("protocol: client binary messages decode and truncated ones are refused") {
    const std::string data = bytes({1, 9, 0, 0, 0}) + "{\"x\":1}";
    auto m = decode_binary(data);
    REQUIRE(m);
    CHECK(std::get<ClientMessageData>(*m).channel_id == 9);
    CHECK(std::get<ClientMessageData>(*m).payload == "{\"x\":1}");

    const std::string call = bytes({2, 4, 0, 0, 0, 8, 0, 0, 0, 4, 0, 0, 0}) + "json" + "[1,2]";
    m = decode_binary(call);
    REQUIRE(m);
    const auto& c = std::get<ServiceCallRequest>(*m);
    CHECK(c.service_id == 4);
    CHECK(c.call_id == 8);
    CHECK(c.encoding == "json");
    CHECK(c.payload == "[1,2]");

    CHECK_FALSE(decode_binary(""));
    CHECK_FALSE(decode_binary(bytes({1, 9, 0})));
    CHECK_FALSE(decode_binary(bytes({2, 4, 0, 0, 0, 8, 0, 0, 0})));
    auto past = decode_binary(bytes({2, 4, 0, 0, 0, 8, 0, 0, 0, 0xff, 0xff, 0xff, 0xff}) + "json");
    REQUIRE_FALSE(past);
    CHECK(past.error().message == "service call request's encoding runs past its end");
    auto unknown = decode_binary(bytes({7, 0}));
    REQUIRE_FALSE(unknown);
    CHECK(unknown.error().message == "unknown binary opcode 0x07");
    DecodeLimits small;
    small.max_binary_bytes = 8;
    CHECK_FALSE(decode_binary(data, small));
}
