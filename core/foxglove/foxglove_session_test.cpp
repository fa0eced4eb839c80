#include <catch2/catch.hpp>

#include "core/foxglove/foxglove_session.hpp"

using namespace rr;
using namespace rr::foxglove;
using nlohmann::json;

namespace {

Channel channel(std::uint32_t id) { return Channel{id, "t" + std::to_string(id), "json", "S", "{}", "jsonschema"}; }

/// The statuses' messages (level 2) of one output.
std::vector<std::string> errors(const Output& out) {
    std::vector<std::string> e;
    for (const auto& t : out.texts) {
        auto j = json::parse(t);
        if (j["op"] == "status" && j["level"] == 2) e.push_back(j["message"]);
    }
    return e;
}

std::string bin(std::initializer_list<int> b) {
    std::string s;
    for (int x : b) s.push_back(static_cast<char>(x));
    return s;
}

}  // namespace

TEST_CASE("session: subscribe and unsubscribe advertised channels") {
    Session s;
    s.channels_advertised({channel(1), channel(2)});
    auto out = s.feed_text(R"({"op":"subscribe","subscriptions":[{"id":10,"channelId":1},{"id":11,"channelId":2}]})");
    CHECK(out.texts.empty());
    REQUIRE(out.events.size() == 2);
    CHECK(std::get<event::Subscribed>(out.events[0]).channel_id == 1);
    CHECK(s.subscription_channel(11) == std::optional<std::uint32_t>(2));

    out = s.feed_text(R"({"op":"unsubscribe","subscriptionIds":[10]})");
    REQUIRE(out.events.size() == 1);
    CHECK(std::get<event::Unsubscribed>(out.events[0]).subscription_id == 10);
    CHECK(s.subscription_count() == 1);

    // A channel that goes away ends its subscription.
    auto ended = s.channels_unadvertised({2});
    REQUIRE(ended.size() == 1);
    CHECK(ended[0].subscription_id == 11);
    CHECK(s.subscription_count() == 0);
    CHECK_FALSE(s.channel_advertised(2));
}

TEST_CASE("session: bad subscriptions get one status and change nothing") {
    Session s;
    s.channels_advertised({channel(1), channel(2)});
    auto out = s.feed_text(R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":1},{"id":2,"channelId":99}]})");
    CHECK(out.events.empty());
    CHECK(errors(out) == std::vector<std::string>{"subscribe refused: channel 99 is not advertised"});
    CHECK(s.subscription_count() == 0);

    REQUIRE(s.feed_text(R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":1}]})").events.size() == 1);
    CHECK(errors(s.feed_text(R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":2}]})")) ==
          std::vector<std::string>{"subscribe refused: subscription id 1 is in use"});
    CHECK(errors(s.feed_text(R"({"op":"subscribe","subscriptions":[{"id":2,"channelId":1}]})")) ==
          std::vector<std::string>{"subscribe refused: channel 1 is already subscribed on this connection"});
    CHECK(errors(s.feed_text(R"({"op":"unsubscribe","subscriptionIds":[5]})")) ==
          std::vector<std::string>{"unsubscribe: no subscription 5"});
    CHECK(errors(s.feed_text("{\"op\":")) == std::vector<std::string>{"message refused: the text message is not JSON"});
    CHECK(errors(s.feed_text(R"({"op":"hello"})")) == std::vector<std::string>{"message refused: unknown op \"hello\""});
    CHECK(s.subscription_count() == 1);
}

TEST_CASE("session: a flood of subscriptions stops at the bound") {
    SessionLimits limits;
    limits.max_subscriptions = 3;
    Session s(limits);
    std::vector<Channel> channels;
    for (std::uint32_t i = 0; i < 10; ++i) channels.push_back(channel(i));
    s.channels_advertised(channels);
    int accepted = 0, refused = 0;
    for (std::uint32_t i = 0; i < 10; ++i) {
        auto out = s.feed_text(json{{"op", "subscribe"}, {"subscriptions", {{{"id", i}, {"channelId", i}}}}}.dump());
        accepted += static_cast<int>(out.events.size());
        refused += static_cast<int>(errors(out).size());
    }
    CHECK(accepted == 3);
    CHECK(refused == 7);
    CHECK(s.subscription_count() == 3);
}

TEST_CASE("session: client channels, publish and unknown channel ids") {
    SessionLimits limits;
    limits.max_client_channels = 2;
    Session s(limits);
    auto out = s.feed_text(R"({"op":"advertise","channels":[{"id":1,"topic":"create/packets","encoding":"json","schemaName":"x"}]})");
    REQUIRE(out.events.size() == 1);
    CHECK(std::get<event::ClientAdvertised>(out.events[0]).channel.topic == "create/packets");
    CHECK(errors(s.feed_text(R"({"op":"advertise","channels":[{"id":2,"topic":"a","encoding":"protobuf","schemaName":"x"}]})")) ==
          std::vector<std::string>{"advertise refused: channel \"a\" has encoding \"protobuf\"; this server takes json"});
    CHECK(errors(s.feed_text(R"({"op":"advertise","channels":[{"id":1,"topic":"a","encoding":"json"}]})")) ==
          std::vector<std::string>{"advertise refused: client channel id 1 is in use"});
    CHECK(errors(s.feed_text(
              R"({"op":"advertise","channels":[{"id":2,"topic":"a","encoding":"json"},{"id":3,"topic":"b","encoding":"json"}]})")) ==
          std::vector<std::string>{"advertise refused: more than 2 client channels on this connection"});

    const std::string msg = bin({1, 1, 0, 0, 0}) + "{\"value\":1}";
    out = s.feed_binary(msg);
    REQUIRE(out.events.size() == 1);
    const auto& p = std::get<event::ClientPublish>(out.events[0]);
    CHECK(p.channel->topic == "create/packets");
    CHECK(p.payload == "{\"value\":1}");
    CHECK(errors(s.feed_binary(bin({1, 7, 0, 0, 0}))) == std::vector<std::string>{"message refused: client channel 7 is not advertised"});
    CHECK(errors(s.feed_binary(bin({9}))) == std::vector<std::string>{"message refused: unknown binary opcode 0x09"});

    out = s.feed_text(R"({"op":"unadvertise","channelIds":[1]})");
    REQUIRE(out.events.size() == 1);
    CHECK(std::get<event::ClientUnadvertised>(out.events[0]).channel.id == 1);
    CHECK(s.client_channel_count() == 0);
    CHECK(errors(s.feed_binary(msg)) == std::vector<std::string>{"message refused: client channel 1 is not advertised"});
}

TEST_CASE("session: service calls are bounded and unknown services fail the call") {
    SessionLimits limits;
    limits.max_calls_in_flight = 1;
    Session s(limits);
    s.services_advertised({Service{4, "create/Drive", "T", {}, {}}});
    const auto call = [](int service, int id) { return bin({2, service, 0, 0, 0, id, 0, 0, 0, 4, 0, 0, 0}) + "json" + "{}"; };
    const std::string first = call(4, 1);  // the event's payload views it
    auto out = s.feed_binary(first);
    REQUIRE(out.events.size() == 1);
    CHECK(std::get<event::ServiceCall>(out.events[0]).payload == "{}");

    out = s.feed_binary(call(4, 2));
    CHECK(out.events.empty());
    REQUIRE(out.texts.size() == 1);
    CHECK(json::parse(out.texts[0]) == json({{"op", "serviceCallFailure"}, {"serviceId", 4}, {"callId", 2},
                                             {"message", "more than 1 service calls in flight on this connection"}}));
    s.call_finished(4, 1);
    CHECK(s.feed_binary(call(4, 2)).events.size() == 1);

    out = s.feed_binary(call(5, 3));
    REQUIRE(out.texts.size() == 1);
    CHECK(json::parse(out.texts[0])["message"] == "service 5 is not advertised");
}

TEST_CASE("session: parameter subscriptions") {
    SessionLimits limits;
    limits.max_parameter_subscriptions = 2;
    Session s(limits);
    auto out = s.feed_text(R"({"op":"subscribeParameterUpdates","parameterNames":["a","a","b"]})");
    REQUIRE(out.events.size() == 1);
    CHECK(std::get<event::ParametersSubscribed>(out.events[0]).names == std::vector<std::string>{"a", "b"});
    CHECK(s.parameter_subscribed("a"));
    CHECK_FALSE(s.parameter_subscribed("c"));
    CHECK(errors(s.feed_text(R"({"op":"subscribeParameterUpdates","parameterNames":["c"]})")).size() == 1);
    s.feed_text(R"({"op":"unsubscribeParameterUpdates","parameterNames":["a"]})");
    CHECK_FALSE(s.parameter_subscribed("a"));
    out = s.feed_text(R"({"op":"subscribeParameterUpdates","parameterNames":[]})");
    CHECK(std::get<event::ParametersSubscribed>(out.events.at(0)).all);
    CHECK(s.parameter_subscribed("anything"));
    CHECK(errors(s.feed_text(R"({"op":"subscribeConnectionGraph"})")).size() == 1);
}
