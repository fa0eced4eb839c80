// JSON Schemas of recorded channels (json_schema.hpp) against the JSON mapping: each schema must accept
// what value_to_json writes for the type and name the fields of structs, pods and namedarrays.
#include <catch2/catch.hpp>

#include "robdef/service_definition_set.hpp"
#include "server/record/json_schema.hpp"

using namespace rr;
namespace record = rr::server::record;
using nlohmann::json;

namespace {

constexpr const char* kDef = R"(service test.rec

enum Mode
    idle = 0,
    run = 1
end

struct Point
    field double x
    field double y
    field Point{list} children
end

namedarray Vec3
    field double x
    field double y
    field double z
end

object Dev
    wire Point pos [readonly]
    wire Vec3[] path [readonly]
    pipe uint8[] frames [readonly]
    event moved(Point where, int32 count)
    property Mode mode [readonly]
    property double[*] grid [readonly]
    property int64{string} counts [readonly]
end
)";

struct SchemaFixture {
    robdef::ServiceDefinitionSet set;
    const robdef::ServiceEntryDefinition* dev = nullptr;
    SchemaFixture() {
        auto r = set.add_text(kDef, "test.rec.robdef");
        INFO((r ? std::string() : r.error().message));
        REQUIRE(r);
        auto ref = set.find("Dev", "test.rec");
        REQUIRE(ref.entry);
        dev = ref.entry;
    }
    const robdef::MemberDefinition& m(const char* name) const { return *dev->find_member(name); }
};

}  // namespace

TEST_CASE("record json schema: a wire of a recursive struct refers to its $defs entry") {
    SchemaFixture f;
    auto s = record::wire_message_schema(f.m("pos").type, f.set, "test.rec", "test.rec.Dev.pos");
    CHECK(s["title"] == "test.rec.Dev.pos");
    CHECK(s["required"] == json({"time", "value"}));
    CHECK(s["properties"]["value"]["$ref"] == "#/$defs/test.rec.Point");
    const auto& point = s["$defs"]["test.rec.Point"];
    CHECK(point["properties"]["x"]["type"] == json({"number", "string"}));
    CHECK(point["properties"]["children"]["type"] == json({"array", "null"}));
    CHECK(point["properties"]["children"]["items"]["$ref"] == "#/$defs/test.rec.Point");
    CHECK(point["type"] == json({"object", "null"}));
}

TEST_CASE("record json schema: arrays, multidim arrays, maps, enums and events") {
    SchemaFixture f;
    auto path = record::wire_message_schema(f.m("path").type, f.set, "test.rec", "p");
    CHECK(path["properties"]["value"]["type"] == "array");
    CHECK(path["$defs"]["test.rec.Vec3"]["required"] == json({"x", "y", "z"}));
    auto frames = record::value_message_schema(f.m("frames").type, f.set, "test.rec", "f");
    CHECK(frames["properties"]["value"]["items"]["type"] == "integer");
    auto mode = record::value_message_schema(f.m("mode").type, f.set, "test.rec", "m");
    CHECK(mode["$defs"]["test.rec.Mode"]["type"] == "integer");
    auto grid = record::value_message_schema(f.m("grid").type, f.set, "test.rec", "g");
    CHECK(grid["properties"]["value"]["required"] == json({"dims", "array"}));
    auto counts = record::value_message_schema(f.m("counts").type, f.set, "test.rec", "c");
    CHECK(counts["properties"]["value"]["additionalProperties"]["type"] == json({"integer", "string"}));
    auto moved = record::event_message_schema(f.m("moved"), f.set, "test.rec", "e");
    CHECK(moved["properties"]["args"]["required"] == json({"where", "count"}));
    CHECK(moved["properties"]["args"]["properties"]["count"]["type"] == "integer");
}
