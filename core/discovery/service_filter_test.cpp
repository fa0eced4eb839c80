#include <catch2/catch.hpp>

#include "core/discovery/service_filter.hpp"

using namespace rr;
using namespace rr::discovery;

namespace {

const NodeID kNode = *NodeID::parse("d835c41d-339c-47a8-84db-f00a8fefd2fa");

ServiceInfo2 reynard() {
    ServiceInfo2 s;
    s.name = "reynard";
    s.root_object_type = "experimental.reynard_the_robot.Reynard";
    s.root_object_implements = {"experimental.robot.Base"};
    s.connection_urls = {"rr+tcp://[fe80::1]:29200/?nodeid=" + kNode.to_string() + "&service=reynard",
                         "rr+local:///?nodeid=" + kNode.to_string() + "&service=reynard"};
    s.node_id = kNode;
    s.node_name = "experimental.reynard_the_robot";
    s.attributes.entries.emplace_back("tags", Value("arm,fox"));
    List l;
    l.items = {Value("lab1"), Value::scalar<std::int32_t>(3), Value("lab2")};
    s.attributes.entries.emplace_back("rooms", Value(l));
    MapString m;
    m.entries.emplace_back("vendor", Value("wason"));
    s.attributes.entries.emplace_back("info", Value(m));
    return s;
}

FilterAttributeGroup group(FilterOperation op, std::vector<std::string> values) {
    FilterAttributeGroup g;
    g.operation = op;
    for (auto& v : values) g.attributes.push_back(FilterAttribute{"", v, {}, ""});
    return g;
}

}  // namespace

TEST_CASE("discovery filter: service type matches the root type or an implemented type") {
    ServiceFilter f;
    CHECK(match_service(f, reynard()));
    CHECK(match_service(f, reynard())->client_service_type == "experimental.reynard_the_robot.Reynard");
    f.service_types = {"experimental.robot.Base"};
    auto m = match_service(f, reynard());
    REQUIRE(m);
    CHECK(m->client_service_type == "experimental.robot.Base");
    f.service_types = {"other.Type"};
    CHECK_FALSE(match_service(f, reynard()));
    // CORE lists a type of the root's own service unqualified.
    auto s = reynard();
    s.root_object_implements = {"Arm"};
    f.service_types = {"experimental.reynard_the_robot.Arm"};
    REQUIRE(match_service(f, s));
    CHECK(match_service(f, s)->client_service_type == "experimental.reynard_the_robot.Arm");
    f.service_types = {"Arm"};
    CHECK(match_service(f, s));
    f.service_types = {"other.Arm"};
    CHECK_FALSE(match_service(f, s));
}

TEST_CASE("discovery filter: nodes by NodeID and/or NodeName") {
    ServiceFilter f;
    f.nodes = {FilterNode{NodeID(), "other"}};
    CHECK_FALSE(match_service(f, reynard()));
    f.nodes.push_back(FilterNode{NodeID(), "experimental.reynard_the_robot"});
    CHECK(match_service(f, reynard()));
    f.nodes = {FilterNode{kNode, ""}};
    CHECK(match_service(f, reynard()));
    f.nodes = {FilterNode{kNode, "wrong name"}};
    CHECK_FALSE(match_service(f, reynard()));
    f.nodes = {FilterNode{}};  // wildcard entry
    CHECK(match_service(f, reynard()));
}

TEST_CASE("discovery filter: service names and transport schemes") {
    ServiceFilter f;
    f.service_names = {"nope"};
    CHECK_FALSE(match_service(f, reynard()));
    f.service_names = {"nope", "reynard"};
    CHECK(match_service(f, reynard()));
    f.transport_schemes = {"rr+local"};
    auto m = match_service(f, reynard());
    REQUIRE(m);
    REQUIRE(m->urls.size() == 1);
    CHECK(m->urls[0].rfind("rr+local://", 0) == 0);
    // No service URL of the scheme: the node's announced index URLs with the service name put in.
    f.transport_schemes = {"rrs+tcp"};
    CHECK_FALSE(match_service(f, reynard()));
    std::vector<std::string> node_urls = {"rrs+tcp://[fe80::1]:1/?nodeid=" + kNode.to_string() +
                                          "&service=RobotRaconteurServiceIndex"};
    m = match_service(f, reynard(), node_urls);
    REQUIRE(m);
    CHECK(m->urls[0] == "rrs+tcp://[fe80::1]:1/?nodeid=" + kNode.to_string() + "&service=reynard");
}

TEST_CASE("discovery filter: attributes as the official attribute groups") {
    ServiceFilter f;
    f.attributes["tags"] = group(FilterOperation::op_or, {"fox"});  // "arm,fox" is split at ','
    CHECK(match_service(f, reynard()));
    f.attributes["tags"] = group(FilterOperation::op_and, {"fox", "arm"});
    CHECK(match_service(f, reynard()));
    f.attributes["tags"] = group(FilterOperation::op_and, {"fox", "cat"});
    CHECK_FALSE(match_service(f, reynard()));
    f.attributes["tags"] = group(FilterOperation::op_nor, {"cat"});
    CHECK(match_service(f, reynard()));
    f.attributes["tags"] = group(FilterOperation::op_nand, {"fox", "arm"});
    CHECK_FALSE(match_service(f, reynard()));

    f.attributes.clear();
    f.attributes["rooms"] = group(FilterOperation::op_or, {"lab2"});  // a list: any item
    CHECK(match_service(f, reynard()));
    FilterAttributeGroup by_name;
    by_name.attributes.push_back(FilterAttribute{"vendor", "wason", {}, ""});
    f.attributes["info"] = by_name;  // a string map: name and value
    CHECK(match_service(f, reynard()));
    f.attributes["info"].attributes[0].name = "maker";
    CHECK_FALSE(match_service(f, reynard()));
    f.attributes_operation = FilterOperation::op_or;  // one of the two attribute names suffices
    CHECK(match_service(f, reynard()));

    // A missing attribute is an empty value list: OR fails, NOR passes.
    ServiceFilter g;
    g.attributes["absent"] = group(FilterOperation::op_or, {"x"});
    CHECK_FALSE(match_service(g, reynard()));
    g.attributes["absent"] = group(FilterOperation::op_nor, {"x"});
    CHECK(match_service(g, reynard()));

    // A caller-supplied matcher (the server passes a compiled regex).
    ServiceFilter r;
    FilterAttributeGroup rg;
    rg.attributes.push_back(FilterAttribute{"", "", [](std::string_view v) { return v.size() == 3 && v[0] == 'f'; }, "f.."});
    r.attributes["tags"] = rg;
    CHECK(match_service(r, reynard()));
    CHECK(parse_filter_operation("NAND") == FilterOperation::op_nand);
    CHECK_FALSE(parse_filter_operation("xor"));
}
