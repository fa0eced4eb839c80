// The gateway's `discovery:` / `discover:` configuration and device naming (docs/gateway-config.md).
// Discovery over the network itself: test/interop/discovery_netns.py.
#include <catch2/catch.hpp>

#include "server/app/gateway_config.hpp"
#include "server/app/gateway_discovery.hpp"

using namespace rr;
using namespace rr::server::app;

namespace {

rr::discovery::ServiceInfo2 service(std::string name, std::string type, std::string tags = "") {
    rr::discovery::ServiceInfo2 s;
    s.name = std::move(name);
    s.root_object_type = std::move(type);
    s.node_name = "lab.robot-1";
    s.node_id = *NodeID::parse("d835c41d-339c-47a8-84db-f00a8fefd2fa");
    s.connection_urls = {"rr+tcp://[fe80::1]:1/?nodeid=d835c41d-339c-47a8-84db-f00a8fefd2fa&service=" + s.name};
    if (!tags.empty()) s.attributes.entries.emplace_back("tags", Value(tags));
    return s;
}

}  // namespace

TEST_CASE("gateway config: discover entries parse into filters") {
    auto c = parse_gateway_config(R"(
discovery:
  interfaces: [veth0]
  max_nodes: 32
  node_expiry_ms: 5000
discover:
  - type: experimental.reynard_the_robot.Reynard
    name: "{service}@{nodename}"
    transports: [rr+tcp]
    max: 2
  - types: [a.B, c.D]
    nodename: lab.robot-1
    service: arm
    attributes:
      tags: fox
      room: [lab1, lab2]
      serial: {regex: "SN-[0-9]+"}
      kind: {all: [x, y], none: [z]}
    attributes_operation: or
)", "t.yaml");
    REQUIRE(c);
    CHECK(c->discovery.enabled);
    CHECK(c->discovery.announce);
    CHECK(c->discovery.interfaces == std::vector<std::string>{"veth0"});
    CHECK(c->discovery.max_nodes == 32);
    CHECK(c->discovery.node_expiry == std::chrono::milliseconds(5000));
    REQUIRE(c->discover.size() == 2);
    const auto& r0 = c->discover[0];
    CHECK(r0.filter.service_types == std::vector<std::string>{"experimental.reynard_the_robot.Reynard"});
    CHECK(r0.filter.max_count == 2);
    CHECK(r0.filter.transport_schemes == std::vector<std::string>{"rr+tcp"});
    const auto& f = c->discover[1].filter;
    CHECK(f.service_types.size() == 2);
    REQUIRE(f.nodes.size() == 1);
    CHECK(f.nodes[0].node_name == "lab.robot-1");
    CHECK(f.attributes.size() == 4);
    CHECK(f.attributes_operation == rr::discovery::FilterOperation::op_or);

    // The parsed filter works: regex and groups included.
    rr::discovery::ServiceFilter only_serial;
    only_serial.attributes["serial"] = f.attributes.at("serial");
    auto s = service("arm", "a.B");
    s.attributes.entries.emplace_back("serial", Value("SN-123"));
    CHECK(rr::discovery::match_service(only_serial, s));
    s.attributes.entries.back().second = Value("SN-12x");
    CHECK_FALSE(rr::discovery::match_service(only_serial, s));
    rr::discovery::ServiceFilter kind;
    kind.attributes["kind"] = f.attributes.at("kind");
    s.attributes.entries.emplace_back("kind", Value("x,y"));
    CHECK(rr::discovery::match_service(kind, s));
    s.attributes.entries.back().second = Value("x,y,z");
    CHECK_FALSE(rr::discovery::match_service(kind, s));
}

TEST_CASE("gateway config: discover mistakes name the key and line") {
    auto bad = [](const char* yaml) {
        auto c = parse_gateway_config(yaml, "t.yaml");
        REQUIRE_FALSE(c);
        return c.error().message;
    };
    CHECK(bad("discover:\n  - type: a.B\n    attributes: {x: {regex: \"([\"}}\n").find("t.yaml:3: discover[0].attributes.x.regex") !=
          std::string::npos);
    CHECK(bad("discover:\n  - transports: [carrier-pigeon]\n").find("unknown transport scheme") != std::string::npos);
    CHECK(bad("discover:\n  - nodeid: nope\n").find("discover[0].nodeid") != std::string::npos);
    CHECK(bad("discover:\n  - typo: a.B\n").find("unknown key") != std::string::npos);
    CHECK(bad("discovery: {max_nodes: 0}\n").find("discovery.max_nodes") != std::string::npos);
    CHECK(bad("discovery: {node_expiry_ms: 10}\n").find("at least 1000") != std::string::npos);
    CHECK(bad("discover: {type: a.B}\n").find("expected a list") != std::string::npos);
    auto on = parse_gateway_config("", "t.yaml");
    REQUIRE(on);
    CHECK(on->discovery.enabled);  // on by default, as on an official server node (issue 40)
}

TEST_CASE("gateway discovery: device names from the template are RR service names") {
    auto s = service("reynard", "x.Y");
    CHECK(discovered_device_name("{service}", s) == "reynard");
    CHECK(discovered_device_name("{service}@{nodename}", s) == "reynard_lab_robot_1");
    CHECK(discovered_device_name("{nodeid}", s) == "d835c41d_339c_47a8_84db_f00a8fefd2fa");
    CHECK(discovered_device_name("9{service}", s) == "d_9reynard");
    CHECK(discovered_device_name("dev_{service}_{unknown}", s) == "dev_reynard__unknown_");
    CHECK(discovered_device_name("", s) == "d_");
}
