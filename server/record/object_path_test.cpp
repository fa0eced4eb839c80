#include <catch2/catch.hpp>

#include "server/record/object_path.hpp"

using namespace rr;
using namespace rr::server;
using namespace rr::server::record;

namespace {

const char* kArmDef = R"(service example.arm
stdver 0.10
import example.tool
object Arm
    objref example.tool.Tool tool
    objref example.tool.Tool{int32} tools
    objref varobject anything
    property int32 x
end
object Cell
    objref Arm{string} arms
    objref Arm main
end
)";
const char* kToolDef = R"(service example.tool
stdver 0.10
object Tool
    wire double state [readonly]
end
)";

}  // namespace

// How a member path splits: base/names/object_path_test.cpp (split_member_path).

TEST_CASE("record: an object below the root is found through the objrefs' declared types") {
    auto types = gateway::DeviceTypes::parse({kArmDef, kToolDef});
    REQUIRE(types);
    const auto& t = **types;

    auto below = object_below(t, "example.arm.Cell", "arms[left.arm].tool");
    REQUIRE(below);
    CHECK(below->path == "arms[left%2earm].tool");
    CHECK(below->object_type == "example.tool.Tool");
    REQUIRE(below->object.entry);
    CHECK(below->object.entry->find_member("state"));
    CHECK(below->object.service->name == "example.tool");

    below = object_below(t, "example.arm.Cell", "main.tools[3]");
    REQUIRE(below);
    CHECK(below->object_type == "example.tool.Tool");

    auto message = [&](std::string_view rel) {
        auto r = object_below(t, "example.arm.Cell", rel);
        REQUIRE_FALSE(r);
        CHECK(r.error().type == MessageErrorType::InvalidArgument);
        return r.error().message;
    };
    CHECK_THAT(message("nothing"), Catch::Contains("has no member \"nothing\""));
    CHECK_THAT(message("main.x"), Catch::Contains("is a property, not an objref"));
    CHECK_THAT(message("main.anything"), Catch::Contains("varobject"));
    CHECK_THAT(message("arms"), Catch::Contains("needs an index"));
    CHECK_THAT(message("main[1]"), Catch::Contains("takes no index"));
    CHECK_THAT(message("main..tool"), Catch::Contains("main..tool"));
    CHECK_THAT(message("arms[x"), Catch::Contains("without ']'"));
}

TEST_CASE("record: channel topics name the object's path between the device and the member") {
    CHECK(channel_topic("create", "", "packets") == "create/packets");
    CHECK(channel_topic("webcam", "Webcams[0]", "FrameStream") == "webcam/Webcams[0]/FrameStream");
    // The path as object_below normalizes it: a '/' in a string index is encoded, so the topic keeps
    // three parts.
    auto types = gateway::DeviceTypes::parse({kArmDef, kToolDef});
    REQUIRE(types);
    auto below = object_below(**types, "example.arm.Cell", "arms[a/b].tool");
    REQUIRE(below);
    CHECK(below->path == "arms[a%2fb].tool");
    CHECK(channel_topic("cell", below->path, "state") == "cell/arms[a%2fb].tool/state");
    below = object_below(**types, "example.arm.Cell", "main.tools[-1]");
    REQUIRE(below);
    CHECK(channel_topic("cell", below->path, "state") == "cell/main.tools[%2d1]/state");
}
