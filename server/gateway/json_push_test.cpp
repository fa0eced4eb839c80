// The JSON WebSocket's pushes (json_push.hpp): one subscriber's push around a shared body, binary
// renderings, and bodies for what the device sent wrong (refused before any conversion).
#include <catch2/catch.hpp>

#include <limits>
#include <stdexcept>

#include "core/session/elements.hpp"
#include "core/value/timespec.hpp"
#include "server/gateway/binary_push.hpp"
#include "server/gateway/json_push.hpp"

using namespace rr;
using namespace rr::server::gateway;
using nlohmann::json;

TEST_CASE("json push: a subscriber's push around a shared body") {
    CHECK(push_text(3, "wire", 0, "{}") == R"({"subscription":3,"kind":"wire"})");
    const std::string body = json_text(json{{"value", 1.5}, {"time", {{"seconds", 1}, {"nanoseconds", 2}}}});
    const auto text = push_text(12, "wire", 4, body);
    auto j = json::parse(text);
    CHECK(j.at("subscription") == 12);
    CHECK(j.at("kind") == "wire");
    CHECK(j.at("dropped") == 4);
    CHECK(j.at("value") == 1.5);
    CHECK(j.at("time").at("nanoseconds") == 2);
    CHECK(text.find("\"dropped\"") < text.find("\"value\""));  // the push's own fields come first
}

TEST_CASE("json push: the head a socket writes before the shared body") {
    const std::string body = R"({"value":2})";
    auto head = push_head(7, "event", 0, body);
    CHECK(head.text() == R"({"subscription":7,"kind":"event",)");
    CHECK(std::string(head.text()) + body.substr(head.body_offset) == push_text(7, "event", 0, body));
    // no members: the head closes the object and the body adds nothing
    head = push_head(7, "wire", 0, "{}");
    CHECK(head.text() == R"({"subscription":7,"kind":"wire"})");
    CHECK(head.body_offset == 2);
    // the longest head fits its buffer and stays valid JSON around the body
    const auto max = std::numeric_limits<std::uint64_t>::max();
    const std::string kind(PushHead::kMaxKind, 'k');
    head = push_head(max, kind, max, body);
    CHECK(head.size <= head.bytes.size());
    auto j = json::parse(std::string(head.text()) + body.substr(head.body_offset));
    CHECK(j.at("subscription") == max);
    CHECK(j.at("dropped") == max);
    CHECK(j.at("kind") == kind);
    CHECK(j.at("value") == 2);
    CHECK_THROWS_AS(push_head(1, kind + "k", 0, body), std::length_error);
}

TEST_CASE("json push: a binary rendering only when the body refers to arrays") {
    BinaryArrays none;
    auto text_only = binary_rendering(json{{"value", 1}}, none);
    CHECK(text_only.arrays == nullptr);
    CHECK(json::parse(text_only.body) == json{{"value", 1}});

    BinaryArrays some;
    some.blobs.push_back(SharedBytes::adopt(std::vector<std::byte>(12, std::byte{7})));
    some.bytes = BinaryArrays::padded(12);
    auto binary = binary_rendering(json{{"value", {{"$binary", 0}}}}, some);
    REQUIRE(binary.arrays != nullptr);
    CHECK(*binary.arrays == binary_push_arrays(some.blobs));

    // An error made after a part set arrays aside refers to none of them.
    auto failed = binary_rendering(json{{"error", {{"name", "x"}, {"message", "y"}}}}, some);
    CHECK(failed.arrays == nullptr);

    auto rendered = render_binary_body([&](BinaryArrays* arrays) {
        arrays->blobs = some.blobs;
        return json{{"args", {{"a", {{"$binary", 0}}}}}};
    });
    CHECK(rendered.arrays != nullptr);
}

TEST_CASE("json push: what the device sent without the elements it needs becomes an error body") {
    JsonApi api({});
    robdef::MemberDefinition member;
    member.name = "moved";
    robdef::TypeDefinition x;
    x.name = "x";
    member.parameters.push_back(x);
    MemberTarget target;
    target.member = &member;

    MessageEntry no_time;
    no_time.elements.push_back(make_scalar_element<double>("packet", 1.0));
    auto wire = wire_push_body(api, no_time, target);
    CHECK(wire.at("error").at("name") == "RobotRaconteur.MessageElementNotFound");
    CHECK(wire.at("error").at("message") == "WirePacket from the device without packet / packettime");
    CHECK_FALSE(wire.contains("value"));

    MessageEntry no_args;
    no_args.elements.push_back(pack_timespec(TimeSpec{1, 2}, "packettime"));
    auto event = event_push_body(api, no_args, target);
    CHECK(event.at("error").at("message") == "event from the device has no \"x\" element");
    CHECK_FALSE(event.contains("args"));
}
