// Object paths (object_path.hpp, object_path_walk.hpp): parsing in both index forms, the normalized
// text, splitting a member off, the walk through the objrefs' declared types, and every error once.
#include <catch2/catch.hpp>

#include "core/names/object_path.hpp"
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

std::string parse_error(std::string_view path, ObjectPathIndexes indexes = ObjectPathIndexes::plain_or_encoded) {
    auto r = parse_object_path(path, indexes);
    REQUIRE_FALSE(r);
    CHECK(r.error().type == MessageErrorType::InvalidArgument);
    return r.error().message;
}

}  // namespace

TEST_CASE("object path: segments, indexes decoded, the service-path text") {
    auto p = parse_object_path("arms[left.arm].tool");
    REQUIRE(p);
    REQUIRE(p->segments.size() == 2);
    CHECK(p->segments[0].name == "arms");
    CHECK(p->segments[0].has_index);
    CHECK(p->segments[0].index == "left.arm");
    CHECK(p->segments[0].encoded_index == "left%2earm");
    CHECK_FALSE(p->segments[1].has_index);
    CHECK(p->text() == "arms[left%2earm].tool");
    // An index already encoded is kept as given (its text is the service's object key), and decoded.
    p = parse_object_path("child_by_int[%2d1].a_b[x_y]");
    REQUIRE(p);
    CHECK(p->segments[0].index == "-1");
    CHECK(p->segments[1].encoded_index == "x_y");
    CHECK(p->text() == "child_by_int[%2d1].a_b[x_y]");
    CHECK(*normalize_object_path("child_by_int[-1]") == "child_by_int[%2d1]");
    CHECK(*normalize_object_path("c[with space]") == "c[with%20space]");
    // From the wire, indexes must be encoded already.
    auto wire = parse_object_path("arms[left%2earm].tool", ObjectPathIndexes::encoded);
    REQUIRE(wire);
    CHECK(wire->segments[0].index == "left.arm");
}

TEST_CASE("object path: every parse error once") {
    CHECK(parse_error("") == "object path \"\" is empty");
    CHECK(parse_error("a..b") == "object path \"a..b\": expected a member name at offset 2");
    CHECK(parse_error("arms[x") == "object path \"arms[x\": '[' without ']'");
    CHECK(parse_error("arms[]") == "object path \"arms[]\": empty index");
    CHECK(parse_error("arms[a b]", ObjectPathIndexes::encoded) ==
          "object path \"arms[a b]\": index \"a b\" is not in service-path encoding (letters, digits, '_', %hh)");
    CHECK(parse_error("arms[1]x") == "object path \"arms[1]x\": unexpected 'x' at offset 7");
    CHECK(parse_error("main.") == "object path \"main.\" ends with '.'");
}

TEST_CASE("object path: a member splits off at its last dot outside brackets") {
    CHECK(split_member_path("packets").object.empty());
    CHECK(split_member_path("packets").member == "packets");
    auto p = split_member_path("arms[left.arm].tool.state");
    CHECK(p.object == "arms[left.arm].tool");
    CHECK(p.member == "state");
    p = split_member_path("cams[a.b]");
    CHECK(p.object.empty());
    CHECK(p.member == "cams[a.b]");
}

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
