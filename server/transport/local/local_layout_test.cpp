// The pure rules of rr+local (local_layout.hpp): names, the .info format, paths, URL checks, search order.
#include <catch2/catch.hpp>

#include "server/transport/local/local_layout.hpp"

using namespace rr;
using namespace rr::server::local;

namespace {

ConnectionUrl url(std::string_view text) {
    auto u = parse_connection_url(text);
    REQUIRE(u);
    return *u;
}

NodeDirectories dirs() {
    NodeDirectories d;
    d.user_run_dir = "/run/u";
    d.system_run_dir = "/run/sys";
    d.user_config_dir = "/cfg";
    d.user_state_dir = "/state";
    return d;
}

}  // namespace

TEST_CASE("local layout: NodeName and user name syntax") {
    for (auto ok : {"a", "probe.node", "Node_1-x.y", "Z9"}) CHECK(is_valid_node_name(ok));
    for (auto bad : {"", "1node", ".x", "-x", "_x", "a/b", "a b", "../x", "a:b", "nodé"}) CHECK_FALSE(is_valid_node_name(bad));
    for (auto ok : {"root", "ann", "user_1-x"}) CHECK(is_valid_local_username(ok));
    for (auto bad : {"", "1a", "a.b", "a b", "a@b"}) CHECK_FALSE(is_valid_local_username(bad));
}

TEST_CASE("local layout: .info format as CORE writes it") {
    // The bytes of an official entry (robotraconteur 1.2.9, by-nodename/<name>.info).
    const std::string official = "ServiceStateNonce: RYfV8yd5UZ60e1DJ\nnodeid: {8642a473-ca2b-4e05-9ffb-9de5a587b7cf}\n"
                                 "nodename: probe.node\npid: 5234\nsocket: /var/run/robotraconteur/root/socket/F8REkmteBSeHuLzd.sock\n"
                                 "username: root\n";
    auto info = parse_info(official);
    CHECK(info.size() == 6);
    CHECK(info["nodename"] == "probe.node");
    CHECK(info["socket"] == "/var/run/robotraconteur/root/socket/F8REkmteBSeHuLzd.sock");
    CHECK(info["nodeid"] == "{8642a473-ca2b-4e05-9ffb-9de5a587b7cf}");
    CHECK(format_info(info) == official);  // key order: byte order, upper case first

    SECTION("blanks, CR, junk lines, values with colons") {
        auto i = parse_info("  key.a+b-c :  v1  \r\n\nnot a line\n: novalue\nsocket: /a:b\n");
        CHECK(i.size() == 2);
        CHECK(i["key.a+b-c"] == "v1");
        CHECK(i["socket"] == "/a:b");
    }
    SECTION("a repeated key keeps the last value (CORE appends a new block on restart)") {
        auto i = parse_info(official + "nodename: probe.node\nsocket: /new.sock\n");
        CHECK(i["socket"] == "/new.sock");
        CHECK(i["pid"] == "5234");
    }
    SECTION("empty values and no final newline") {
        auto i = parse_info("nodename: \nsocket: /s");
        CHECK(i["nodename"].empty());
        CHECK(i["socket"] == "/s");
    }
}

TEST_CASE("local layout: paths below the node directories") {
    auto d = dirs();
    auto id = *NodeID::parse("{8642a473-ca2b-4e05-9ffb-9de5a587b7cf}");
    CHECK(private_entry_dir(d) == "/run/u/transport/local");
    CHECK(private_socket_dir(d) == "/run/u/socket");
    CHECK(public_search_dir(d) == "/run/sys/transport/local");
    CHECK(public_user_dir(d, "ann") == "/run/sys/transport/local/ann");
    CHECK(by_nodeid_file("/e", id, "info") == "/e/by-nodeid/8642a473-ca2b-4e05-9ffb-9de5a587b7cf.info");
    CHECK(by_nodename_file("/e", "probe.node", "pid") == "/e/by-nodename/probe.node.pid");
    CHECK(nodename_lock_file(d, "n") == "/run/u/nodeids/n.pid");
    CHECK(nodeid_cache_file(d, "n") == "/cfg/nodeids/n");
    CHECK(nodeid_state_file(d, "n") == "/state/nodeids/n");
    CHECK(local_listen_url(id) == "rr+local:///?nodeid=8642a473-ca2b-4e05-9ffb-9de5a587b7cf");
}

TEST_CASE("local layout: what an rr+local URL asks for") {
    auto t = local_target(url("rr+local:///?nodename=probe.node&service=S"));
    REQUIRE(t);
    CHECK(t->node_name == "probe.node");
    CHECK(t->node_id.is_any());
    CHECK(t->user.empty());

    t = local_target(url("rr+local:///?nodeid=8642a473-ca2b-4e05-9ffb-9de5a587b7cf&nodename=n&service=S"));
    REQUIRE(t);
    CHECK(t->node_id.to_string() == "8642a473-ca2b-4e05-9ffb-9de5a587b7cf");
    CHECK(t->node_name == "n");

    t = local_target(url("rr+local://localhost/?nodeid={8642a473-ca2b-4e05-9ffb-9de5a587b7cf}&service=S"));
    REQUIRE(t);
    t = local_target(url("rr+local://ann@localhost/?nodename=n&service=S"));
    REQUIRE(t);
    CHECK(t->user == "ann");

    struct Bad {
        const char* url;
        const char* says;
    };
    for (auto [u, says] : {Bad{"rr+local://otherhost/?nodename=n&service=S", "host must be empty or \"localhost\""},
                           Bad{"rr+local:///foo?nodename=n&service=S", "path must be \"/\""},
                           Bad{"rr+local:///?service=S", "a NodeID and/or a NodeName"},
                           Bad{"rr+local:///?nodename=../x&service=S", "invalid NodeName"},
                           Bad{"rr+local://1x@localhost/?nodename=n&service=S", "invalid user name"},
                           Bad{"rr+local://ann@/?nodename=n&service=S", "user@localhost"},
                           Bad{"rr+tcp://127.0.0.1:1/?nodename=n&service=S", "not rr+local"}}) {
        INFO(u);
        auto r = local_target(url(u));
        REQUIRE_FALSE(r);
        CHECK(r.error().type == MessageErrorType::InvalidArgument);
        CHECK_THAT(r.error().message, Catch::Contains(says));
    }
    // A port is refused by the URL parser already.
    auto p = parse_connection_url("rr+local://localhost:1234/?nodename=n&service=S");
    REQUIRE_FALSE(p);
    CHECK_THAT(p.error().message, Catch::Contains("no port"));
}

TEST_CASE("local layout: search order") {
    auto d = dirs();
    auto paths = [](const std::vector<SearchDir>& v) {
        std::vector<std::string> out;
        for (const auto& s : v) out.push_back(s.path);
        return out;
    };
    LocalTarget t;
    t.node_name = "n";
    CHECK(paths(search_dirs(d, "ann", t)) ==
          std::vector<std::string>{"/run/u/transport/local", "/run/sys/transport/local/ann", "/run/sys/transport/local/root"});
    // Root's own public dir is root's public dir: listed once.
    CHECK(paths(search_dirs(d, "root", t)) == std::vector<std::string>{"/run/u/transport/local", "/run/sys/transport/local/root"});
    t.user = "ann";
    CHECK(paths(search_dirs(d, "ann", t)) == std::vector<std::string>{"/run/u/transport/local", "/run/sys/transport/local/ann"});
    t.user = "bob";
    CHECK(paths(search_dirs(d, "ann", t)) == std::vector<std::string>{"/run/sys/transport/local/bob"});
    CHECK_FALSE(search_dirs(d, "ann", t).front().path.empty());
    CHECK(search_dirs(d, "ann", t).front().is_public);
}
