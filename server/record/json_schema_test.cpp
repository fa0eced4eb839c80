// JSON Schemas of recorded channels (json_schema.hpp) against the JSON mapping: each schema must accept
// what value_to_json writes for the type and name the fields of structs, pods and namedarrays.
#include <catch2/catch.hpp>

#include "robdef/service_definition_set.hpp"
#include "server/record/json_schema.hpp"

using namespace rr;
namespace record = rr::server::record;
using nlohmann::json;

namespace {

constexpr const char* kSchemaDef = R"(service test.rec

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
        auto r = set.add_text(kSchemaDef, "test.rec.robdef");
        INFO((r ? std::string() : r.error().message));
        REQUIRE(r);
        auto ref = set.find("Dev", "test.rec");
        REQUIRE(ref.entry);
        dev = ref.entry;
    }
    const robdef::MemberDefinition& m(const char* name) const { return *dev->find_member(name); }
};

}  // namespace

TEST_CASE("record json schema: a recursive struct is inlined, itself inside as an object without fields") {
    SchemaFixture f;
    auto s = record::wire_message_schema(f.m("pos").type, f.set, "test.rec", "test.rec.Dev.pos");
    CHECK(s["title"] == "test.rec.Dev.pos");
    CHECK(s["type"] == "object");
    CHECK(s["required"] == json({"time"}));  // a struct value may be null: left out then, so not required
    CHECK_FALSE(s.contains("$defs"));
    const auto& point = s["properties"]["value"];
    CHECK(point["type"] == "object");
    CHECK(point["title"] == "test.rec.Point");
    CHECK(point["properties"]["x"]["type"] == "number");
    CHECK(point["properties"]["children"]["type"] == "array");
    const auto& child = point["properties"]["children"]["items"];
    CHECK(child["type"] == "object");
    CHECK(child["properties"] == json::object());
    CHECK(s["properties"]["time"]["properties"]["seconds"]["type"] == "integer");
    CHECK(s.dump().find("$ref") == std::string::npos);
}

TEST_CASE("record json schema: arrays, multidim arrays, maps, enums and events") {
    SchemaFixture f;
    auto path = record::wire_message_schema(f.m("path").type, f.set, "test.rec", "p");
    CHECK(path["properties"]["value"]["type"] == "array");
    CHECK(path["properties"]["value"]["items"]["required"] == json({"x", "y", "z"}));
    auto frames = record::value_message_schema(f.m("frames").type, f.set, "test.rec", "f");
    CHECK(frames["properties"]["value"]["items"]["type"] == "integer");
    auto mode = record::value_message_schema(f.m("mode").type, f.set, "test.rec", "m");
    CHECK(mode["properties"]["value"]["type"] == "integer");
    CHECK(mode["properties"]["value"]["title"] == "test.rec.Mode");
    auto grid = record::value_message_schema(f.m("grid").type, f.set, "test.rec", "g");
    CHECK(grid["properties"]["value"]["required"] == json({"dims", "array"}));
    CHECK(grid["properties"]["value"]["properties"]["array"]["items"]["type"] == "number");
    auto counts = record::value_message_schema(f.m("counts").type, f.set, "test.rec", "c");
    CHECK(counts["properties"]["value"]["type"] == "object");
    CHECK(counts["properties"]["value"]["properties"] == json::object());
    CHECK(counts["properties"]["value"]["additionalProperties"]["type"] == "integer");
    auto moved = record::event_message_schema(f.m("moved"), f.set, "test.rec", "e");
    CHECK(moved["properties"]["args"]["required"] == json({"count"}));  // where: a struct, may be null
    CHECK(moved["properties"]["args"]["properties"]["count"]["type"] == "integer");
}

TEST_CASE("record json schema: what one type cannot describe is left out and named") {
    robdef::ServiceDefinitionSet set;
    auto r = set.add_text(R"(service test.odd

struct Holder
    field double[]{list} rows
    field varvalue any
    field int32 n
end

object Dev
    wire Holder h [readonly]
    wire double[]{list} rows [readonly]
end
)", "test.odd.robdef");
    REQUIRE(r);
    const auto* dev = set.find("Dev", "test.odd").entry;
    REQUIRE(dev);
    auto h = record::wire_message_schema(dev->find_member("h")->type, set, "test.odd", "h");
    const auto& holder = h["properties"]["value"];
    CHECK_FALSE(holder["properties"].contains("rows"));
    CHECK(holder["required"] == json({"n"}));  // a varvalue may be null: left out then, so not required
    CHECK(holder["description"].get<std::string>().find("[\"rows\"]") != std::string::npos);
    CHECK(holder["properties"]["any"]["type"] == "object");
    auto rows = record::wire_message_schema(dev->find_member("rows")->type, set, "test.odd", "rows");
    CHECK_FALSE(rows["properties"].contains("value"));
    CHECK(rows["required"] == json({"time"}));
}
