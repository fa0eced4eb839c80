// The JSON WebSocket's pushes (json_push.hpp): one subscriber's push around a shared body, binary
// renderings, and bodies for what the device sent wrong (refused before any conversion).
#include <catch2/catch.hpp>

#include <limits>
#include <stdexcept>

#include "base/message/error_entry.hpp"
#include "core/session/elements.hpp"
#include "core/value/numeric_array.hpp"
#include "core/value/pack_value.hpp"
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

namespace {

constexpr const char* kPushDef = R"(service example.push

stdver 0.10

struct Pose
    field double x
    field string frame
end

object Sensor
    wire double[] samples [readonly]
    wire uint8[] frame [readonly]
    wire int64 ticks [readonly]
    wire cdouble[2] phasor [readonly]
    wire bool[4-] flags [readonly]
    wire Pose pose [readonly]
    wire string label [readonly]
    event moved(double y, int32[] ids, bool done)
    event noted(string text, double at)
    event nothing()
    pipe double[] stream [readonly]
    pipe Pose poses [readonly]
end
)";

struct PushTargets {
    std::shared_ptr<const DeviceTypes> types;
    DeviceTypes::Object object;

    PushTargets() {
        auto t = DeviceTypes::parse({kPushDef});
        INFO((t ? std::string() : t.error().message));
        REQUIRE(t);
        types = *t;
        auto o = types->find_object("example.push.Sensor");
        REQUIRE(o);
        object = *o;
    }
    MemberTarget operator()(std::string_view member) const {
        MemberTarget target;
        target.types = types;
        target.service = object.service;
        target.object = object.entry;
        target.member = object.entry->find_member(member);
        REQUIRE(target.member);
        return target;
    }
};

template <class T>
MessageElement array_of(std::string name, std::vector<T> items) {
    MessageElement e;
    e.name = std::move(name);
    e.type = numeric_type_v<T>;
    std::vector<std::byte> bytes(items.size() * sizeof(T));
    for (std::size_t i = 0; i < items.size(); ++i) rr::detail::store_item<T>(bytes.data() + i * sizeof(T), items[i]);
    e.data = SharedBytes::adopt(std::move(bytes));
    return e;
}

MessageEntry wire_packet(MessageElement value, TimeSpec time = {1700000000, 123456789}) {
    MessageEntry e;
    value.name = "packet";
    e.elements.push_back(std::move(value));
    e.elements.push_back(pack_timespec(time, "packettime"));
    return e;
}

}  // namespace

namespace {
// The packet of the first case for `member`.
template <class Cases>
const MessageElement& c_value(const Cases& cases, std::string_view member) {
    for (const auto& c : cases)
        if (c.member == member) return c.packet;
    throw std::logic_error("no case");
}
}  // namespace

TEST_CASE("json push: a wire value's text, written straight from its element, is the general path's") {
    JsonApi api({});
    PushTargets targets;
    struct Case {
        const char* member;
        MessageElement packet;
    };
    const double nan = std::numeric_limits<double>::quiet_NaN();
    std::vector<Case> cases;
    cases.push_back({"samples", array_of<double>("", {0.0, -1.5, 0.1, 1e300, nan, 12345678.0})});
    cases.push_back({"samples", array_of<double>("", {})});
    cases.push_back({"frame", array_of<std::uint8_t>("", {0, 7, 255, 128})});
    cases.push_back({"ticks", make_scalar_element<std::int64_t>("", std::int64_t{1} << 60)});
    cases.push_back({"phasor", array_of<cdouble>("", {{1, -2}, {0.25, nan}})});
    cases.push_back({"flags", array_of<bool>("", {true, false, true})});
    // Named types, strings and errors: the same text either way.
    Structure pose{"example.push.Pose", {{"x", Value::scalar(2.5)}, {"frame", Value(std::string("map"))}}};
    auto pose_el = pack_value(Value(std::move(pose)), targets("pose").member->type, "packet", targets.types->set(),
                              "example.push");
    REQUIRE(pose_el);
    cases.push_back({"pose", *pose_el});
    cases.push_back({"label", make_string_element("", "tab\there \"quoted\"")});
    cases.push_back({"samples", array_of<std::int32_t>("", {1, 2})});          // another numeric type
    cases.push_back({"ticks", array_of<std::int64_t>("", {1, 2})});            // two items for a scalar
    cases.push_back({"phasor", array_of<cdouble>("", {{1, 2}})});              // one for exactly two
    cases.push_back({"flags", array_of<bool>("", {true, true, true, true, true})});  // five for at most four
    for (auto& c : cases) {
        const MemberTarget target = targets(c.member);
        const MessageEntry packet = wire_packet(c.packet);
        INFO(c.member);
        CHECK(wire_push_text(api, packet, target) == json_text(wire_push_body(api, packet, target)));
    }
    // The struct and the string go the direct way too: DeviceTypes has a plan for them, compiled once.
    const Limits limits = api.options().limits;
    for (const char* member : {"pose", "label", "samples"}) {
        const MemberTarget t = targets(member);
        const auto* plan = targets.types->json_text_plan(t.member->type, t.context(), limits);
        INFO(member);
        REQUIRE(plan);
        CHECK(targets.types->json_text_plan(t.member->type, t.context(), limits) == plan);
        std::string direct;
        REQUIRE(plan->append(direct, c_value(cases, member)));
        CHECK(wire_push_text(api, wire_packet(c_value(cases, member)), t).find(direct) != std::string::npos);
    }
    // Direct text really is what the direct path wrote: a value the general path would render too.
    const auto text = wire_push_text(api, wire_packet(array_of<double>("", {1.0, 2.5})), targets("samples"));
    CHECK(text == R"({"time":{"nanoseconds":123456789,"seconds":1700000000},"value":[1.0,2.5]})");
    // A packet without its time, or with a broken one, is the general path's error body.
    MessageEntry no_time;
    no_time.elements.push_back(make_scalar_element<double>("packet", 1.0));
    CHECK(json::parse(wire_push_text(api, no_time, targets("samples"))).at("error").at("name") ==
          "RobotRaconteur.MessageElementNotFound");
    MessageEntry bad_time = wire_packet(array_of<double>("", {1.0}));
    bad_time.elements[1] = make_scalar_element<double>("packettime", 1.0);
    CHECK(wire_push_text(api, bad_time, targets("samples")) == json_text(wire_push_body(api, bad_time, targets("samples"))));
    CHECK(json::parse(wire_push_text(api, bad_time, targets("samples"))).contains("error"));
}

TEST_CASE("json push: an event's text, written straight from its elements, is the general path's") {
    JsonApi api({});
    PushTargets targets;
    auto event_of = [](std::vector<MessageElement> elements) {
        MessageEntry e;
        e.elements = std::move(elements);
        return e;
    };
    std::vector<std::pair<const char*, MessageEntry>> cases;
    cases.emplace_back("moved", event_of({make_scalar_element<double>("y", 0.5), array_of<std::int32_t>("ids", {3, -4}),
                                          make_scalar_element<bool>("done", true)}));
    // Elements in another order than the parameters: the same object.
    cases.emplace_back("moved", event_of({make_scalar_element<bool>("done", false), array_of<std::int32_t>("ids", {}),
                                          make_scalar_element<double>("y", -0.0)}));
    cases.emplace_back("nothing", event_of({}));
    cases.emplace_back("noted", event_of({make_string_element("text", "hi"), make_scalar_element<double>("at", 2)}));
    cases.emplace_back("moved", event_of({make_scalar_element<double>("y", 1), make_scalar_element<bool>("done", true)}));
    cases.emplace_back("moved", event_of({make_scalar_element<double>("y", 1), array_of<double>("ids", {1}),
                                          make_scalar_element<bool>("done", true)}));
    for (auto& [member, event] : cases) {
        const MemberTarget target = targets(member);
        INFO(member);
        CHECK(event_push_text(api, event, target) == json_text(event_push_body(api, event, target)));
    }
    CHECK(event_push_text(api, cases[0].second, targets("moved")) == R"({"args":{"done":true,"ids":[3,-4],"y":0.5}})");
    CHECK(event_push_text(api, cases[2].second, targets("nothing")) == R"({"args":{}})");
    CHECK(json::parse(event_push_text(api, cases[4].second, targets("moved"))).contains("error"));
}

TEST_CASE("json push: an event with two parameters of one name (a received, unverified definition) is the general path's text") {
    auto types = DeviceTypes::parse({"service example.twice\nstdver 0.10\nobject O\n    event twice(double a, double a)\nend\n"});
    REQUIRE(types);
    auto o = (*types)->find_object("example.twice.O");
    REQUIRE(o);
    MemberTarget target;
    target.types = *types;
    target.service = o->service;
    target.object = o->entry;
    target.member = o->entry->find_member("twice");
    REQUIRE(target.member);
    REQUIRE(target.member->parameters.size() == 2);
    JsonApi api({});
    MessageEntry event;
    event.elements.push_back(make_scalar_element<double>("a", 1.5));
    const std::string text = event_push_text(api, event, target);
    CHECK(text == json_text(event_push_body(api, event, target)));
    CHECK(text == R"({"args":{"a":1.5}})");
}

TEST_CASE("json push: a pipe packet's text, written straight from its element, is the general path's") {
    JsonApi api({});
    PushTargets targets;
    auto general = [](std::uint64_t sid, std::uint64_t dropped, const json& value) {
        json msg{{"subscription", sid}, {"kind", "pipe"}, {"value", value}};
        if (dropped) msg["dropped"] = dropped;
        return json_text(msg);
    };
    const auto samples = array_of<double>("", {1.0, -0.5, 1e-9});
    for (std::uint64_t dropped : {0, 3}) {
        auto push = pipe_push(api, 7, samples, targets("stream"), dropped, false);
        CHECK(push.arrays == nullptr);
        CHECK(push.body == general(7, dropped, json{1.0, -0.5, 1e-9}));
    }
    // Binary subscribers and mismatched packets keep the general path; a struct is written directly.
    auto binary = pipe_push(api, 7, samples, targets("stream"), 0, true);
    CHECK(binary.arrays != nullptr);
    Structure pose{"example.push.Pose", {{"x", Value::scalar(2.5)}, {"frame", Value(std::string("map"))}}};
    auto pose_el = pack_value(Value(std::move(pose)), targets("poses").member->type, "packet", targets.types->set(),
                              "example.push");
    REQUIRE(pose_el);
    auto named = pipe_push(api, 8, *pose_el, targets("poses"), 0, false);
    CHECK(named.body == general(8, 0, json{{"frame", "map"}, {"x", 2.5}}));
    auto wrong = pipe_push(api, 9, array_of<std::int32_t>("", {1}), targets("stream"), 2, false);
    auto j = json::parse(wrong.body);
    CHECK(j.at("error").at("name") == "RobotRaconteur.DataTypeMismatch");
    CHECK(j.at("dropped") == 2);
    CHECK_FALSE(j.contains("value"));
}
