// `rr discover` command line and NodeName URLs (docs/cli.md). The command against real nodes:
// test/interop/discovery_netns.py.
#include <catch2/catch.hpp>

#include "server/cli/cli_discover.hpp"
#include "server/cli/cli_options.hpp"

using namespace rr;
using namespace rr::cli;

TEST_CASE("rr discover: options") {
    auto cl = parse_command_line({"discover", "--type", "a.B", "--type=c.D", "--json", "--interface", "veth0"});
    REQUIRE(cl);
    CHECK(cl->kind == CommandKind::discover);
    CHECK(cl->types == std::vector<std::string>{"a.B", "c.D"});
    CHECK(cl->json);
    CHECK(cl->interfaces == std::vector<std::string>{"veth0"});
    CHECK(cl->timeout_s == 5);  // discover's own default
    auto t = parse_command_line({"discover", "--timeout", "2.5"});
    REQUIRE(t);
    CHECK(t->timeout_s == 2.5);
    CHECK_FALSE(parse_command_line({"discover", "rr+tcp://x:1/?service=s"}));
    CHECK_FALSE(parse_command_line({"discover", "--count", "3"}));
    CHECK_FALSE(parse_command_line({"info", "rr+tcp://x:1/?service=s", "--json"}));
    CHECK_FALSE(parse_command_line({"discover", "--type"}));
    CHECK_FALSE(help_text("discover").empty());
}

TEST_CASE("rr: URLs that name a node but no host are resolved by discovery") {
    CHECK(needs_discovery(*parse_connection_url("rr+tcp:///?nodename=lab.robot&service=s")));
    CHECK(needs_discovery(*parse_connection_url("rr+tcp:///?nodeid=d835c41d-339c-47a8-84db-f00a8fefd2fa")));
    CHECK_FALSE(needs_discovery(*parse_connection_url("rr+tcp://localhost:1/?nodename=lab.robot&service=s")));
    CHECK_FALSE(needs_discovery(*parse_connection_url("rr+tcp:///?service=s")));
    CHECK_FALSE(needs_discovery(*parse_connection_url("rr+ws:///?nodename=x&service=s")));
}
