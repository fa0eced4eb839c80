// Walking an object path through the objrefs' declared types (object_path_walk.hpp) over a definition
// set, and every walk error once.
#include <catch2/catch.hpp>

#include "core/names/object_path_walk.hpp"

using namespace rr;

namespace {

const char* kArmDef = R"(service example.arm
stdver 0.10
import example.tool
object Arm
    objref example.tool.Tool tool
    objref example.tool.Tool{int32} tools
    objref varobject anything
    objref example.tool.Missing lost
    property int32 x
end
object Cell
    objref Arm{string} arms
    objref Arm[] row
    objref Arm main
end
)";
const char* kToolDef = R"(service example.tool
stdver 0.10
object Tool
    wire double state [readonly]
end
)";

robdef::ServiceDefinitionSet definitions() {
    robdef::ServiceDefinitionSet set;
    REQUIRE(set.add_text(kToolDef, "tool"));
    REQUIRE(set.add_text(kArmDef, "arm"));
    return set;
}

}  // namespace

TEST_CASE("object path: walked through the objrefs' declared types") {
    const auto set = definitions();
    auto walk = [&](std::string_view text, std::string_view root = "example.arm.Cell") {
        auto path = parse_object_path(text);
        REQUIRE(path);
        return walk_object_path(set, root, *path, text);
    };
    auto at = walk("arms[left.arm].tool");
    REQUIRE(at);
    CHECK(at->object_type == "example.tool.Tool");
    CHECK(at->service->name == "example.tool");
    CHECK(at->object->find_member("state"));
    at = walk("main.tools[3]");
    REQUIRE(at);
    CHECK(at->object_type == "example.tool.Tool");
    at = walk("row[0]");
    REQUIRE(at);
    CHECK(at->object_type == "example.arm.Arm");
    CHECK(find_object_type(set, "example.arm.Arm"));
    CHECK_FALSE(find_object_type(set, "example.arm.Nope"));
    CHECK_FALSE(find_object_type(set, "Arm"));
}

TEST_CASE("object path: every walk error once") {
    const auto set = definitions();
    auto error = [&](std::string_view text, std::string_view root = "example.arm.Cell") {
        auto path = parse_object_path(text);
        REQUIRE(path);
        auto r = walk_object_path(set, root, *path, text);
        REQUIRE_FALSE(r);
        CHECK(r.error().type == MessageErrorType::InvalidArgument);
        return r.error().message;
    };
    CHECK(error("main", "example.arm.Nope") == "unknown object type example.arm.Nope");
    CHECK(error("nothing") == "object \"nothing\": example.arm.Cell has no member \"nothing\"");
    CHECK(error("main.x") == "object \"main.x\": example.arm.Arm member \"x\" is a property, not an objref");
    CHECK(error("main.anything") == "object \"main.anything\": example.arm.Arm objref \"anything\" is a varobject (its type is known only to the device)");
    CHECK(error("arms") == "object \"arms\": example.arm.Cell objref \"arms\" needs an index (Arm{string})");
    CHECK(error("main[1]") == "object \"main[1]\": example.arm.Cell objref \"main\" takes no index");
    CHECK(error("main.lost") == "object \"main.lost\": example.arm.Arm objref \"lost\": unknown object type example.tool.Missing");
}
