// rr+local over real Unix sockets in a temporary tree of node directories: a named node found by
// NodeName, by NodeID and by both, the entries it publishes (as CORE writes them) and removes, the
// NodeID cache, unknown names, stale entries, a directory or socket without permission, a NodeName
// taken (in this process and by another process), and the service index's rr+local URLs.
#include <catch2/catch.hpp>

#include <atomic>
#include <future>
#include <fstream>
#include <thread>

#include <grp.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include "server/client/client.hpp"
#include "server/client/raw_client.hpp"
#include "server/node/node.hpp"
#include "server/service/test_raw_service.hpp"
#include "server/transport/local/local_connector.hpp"
#include "server/transport/local/local_entries.hpp"
#include "server/transport/local/local_layout.hpp"
#include "server/transport/local/local_listener.hpp"
#include "server/transport/local/local_test_support.hpp"
#include "test/support/eventually.hpp"
#include "test/support/skip.hpp"
#include "server/transport/local/node_identity.hpp"

extern char** environ;

using namespace rr;
using namespace rr::server;
using namespace rr::server::local;
using namespace std::chrono_literals;
using rr::client::Client;
using rr::server::local::testing::TempNodeDirs;
using rr::server::local::testing::unique_node_name;
using rr::testing::eventually;

namespace {

// Routes the typed client's rr+local to `dirs` for the scope; back to the process's dirs after.
struct LocalTransportFor {
    explicit LocalTransportFor(const NodeDirectories& dirs) {
        default_transports().add("rr+local", std::make_shared<LocalConnector>([dirs] { return dirs; }));
    }
    ~LocalTransportFor() { default_transports().add("rr+local", std::make_shared<LocalConnector>()); }
};

struct NamedNode {
    std::shared_ptr<Node> node;
    std::shared_ptr<LocalListener> listener;
};

NamedNode start_named(const NodeDirectories& dirs, const std::string& name, LocalListenOptions opts = {}) {
    auto r = reserve_node_name(dirs, name);
    REQUIRE(r);
    NodeOptions o;
    o.node_id = r->node_id;
    o.node_name = name;
    o.threads = 2;
    auto node = Node::create(o);
    REQUIRE(node->register_service(std::make_shared<server::testing::RawTestService>()));
    opts.dirs = dirs;
    auto l = listen_local(node, opts, std::move(*r));
    REQUIRE(l);
    return {node, *l};
}

std::string read_file(const std::string& path) {
    auto r = read_small_file(path, 1 << 20);
    REQUIRE(r);
    return *r;
}

void write_file(const std::string& path, const std::string& text) {
    std::ofstream f(path, std::ios::binary | std::ios::trunc);
    f << text;
    REQUIRE(f.good());
}

bool exists(const std::string& p) {
    struct stat st {};
    return ::lstat(p.c_str(), &st) == 0;
}

unsigned mode_of(const std::string& p) {
    struct stat st {};
    REQUIRE(::lstat(p.c_str(), &st) == 0);
    return st.st_mode & 07777;
}

Result<std::shared_ptr<Client>> connect(client::IoThreads& io, const std::string& url) {
    client::ClientOptions o;
    o.request_timeout = 30000ms;  // a bound on a hang
    return Client::connect(io.executor(), url, o);
}

// A Unix socket file nobody listens on any more (connect: ECONNREFUSED).
void make_dead_socket(const std::string& path) {
    int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
    REQUIRE(fd >= 0);
    sockaddr_un a{};
    a.sun_family = AF_UNIX;
    std::snprintf(a.sun_path, sizeof(a.sun_path), "%s", path.c_str());
    REQUIRE(::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof(a)) == 0);
    ::close(fd);
}

// Runs `fn` with the effective user and group `nobody` (65534) and no supplementary groups, then
// restores root's. Only for a process whose real user is root.
template <class Fn>
void as_nobody(Fn fn) {
    std::vector<gid_t> groups(64);
    int n = ::getgroups(static_cast<int>(groups.size()), groups.data());
    REQUIRE(n >= 0);
    groups.resize(static_cast<std::size_t>(n));
    REQUIRE(::setgroups(0, nullptr) == 0);
    REQUIRE(::setegid(65534) == 0);
    REQUIRE(::seteuid(65534) == 0);
    fn();
    REQUIRE(::seteuid(0) == 0);
    REQUIRE(::setegid(0) == 0);
    REQUIRE(::setgroups(groups.size(), groups.data()) == 0);
}

}  // namespace

TEST_CASE("local: a named node is found by NodeName, NodeID and both, its entries are CORE's") {
    TempNodeDirs tmp;
    LocalTransportFor route(tmp.dirs);
    const std::string name = unique_node_name("local.basic");
    auto [node, listener] = start_named(tmp.dirs, name);
    const std::string id = node->node_id().to_string();

    // Entries: by-nodeid and by-nodename, .pid and .info, mode 0640; the socket, mode 0770.
    const std::string entry_dir = tmp.dirs.user_run_dir + "/transport/local";
    CHECK(listener->entry_dir() == entry_dir);
    const std::string info_name = entry_dir + "/by-nodename/" + name + ".info";
    const std::string info_id = entry_dir + "/by-nodeid/" + id + ".info";
    CHECK(listener->info_files() == std::vector<std::string>{info_id, info_name});
    for (const auto& f : {info_name, info_id, entry_dir + "/by-nodename/" + name + ".pid", entry_dir + "/by-nodeid/" + id + ".pid"})
        CHECK(mode_of(f) == 0640);
    CHECK(read_file(entry_dir + "/by-nodeid/" + id + ".pid") == std::to_string(::getpid()));
    auto info = parse_info(read_file(info_name));
    CHECK(read_file(info_name) == read_file(info_id));
    CHECK(info["nodename"] == name);
    CHECK(info["nodeid"] == node->node_id().to_braced_string());
    CHECK(info["socket"] == listener->socket_path());
    CHECK(info["pid"] == std::to_string(::getpid()));
    CHECK(info["username"] == *current_user_name());
    CHECK(info["ServiceStateNonce"].size() == 16);
    CHECK(format_info(info) == read_file(info_name));  // nothing but those keys, in CORE's order
    CHECK(listener->socket_path().rfind(tmp.dirs.user_run_dir + "/socket/", 0) == 0);
    CHECK(listener->socket_path().size() == (tmp.dirs.user_run_dir + "/socket/").size() + 16 + 5);
    CHECK(mode_of(listener->socket_path()) == 0770);
    CHECK(listener->url() == "rr+local:///?nodeid=" + id);

    client::IoThreads io{1};
    for (const std::string& url : {"rr+local:///?nodename=" + name + "&service=svc", "rr+local:///?nodeid=" + id + "&service=svc",
                                   "rr+local:///?nodeid={" + id + "}&nodename=" + name + "&service=svc",
                                   "rr+local://localhost/?nodename=" + name + "&service=svc",
                                   "rr+local://" + *current_user_name() + "@localhost/?nodename=" + name + "&service=svc"}) {
        INFO(url);
        auto c = connect(io, url);
        REQUIRE(c);
        CHECK((*c)->remote_node_id() == node->node_id());
        auto x = (*c)->root().get("x");
        REQUIRE(x);
        CHECK(*x == Value::scalar(42.5));
        CHECK((*c)->close_wait().ok());
    }

    // The entries carry the node's one ServiceStateNonce; a change of services renews it in both
    // entries (CORE LocalNodeServicesChanged writes the node's GetServiceStateNonce()).
    const auto nonce = info["ServiceStateNonce"];
    CHECK(nonce == node->service_state_nonce());
    CHECK(listener->service_state_nonce() == nonce);
    node->unregister_service("svc");
    auto after = parse_info(read_file(info_name));
    CHECK(after["ServiceStateNonce"] != nonce);
    CHECK(after["ServiceStateNonce"] == node->service_state_nonce());
    CHECK(read_file(info_name) == read_file(info_id));
    REQUIRE(node->register_service(std::make_shared<server::testing::RawTestService>()));
    CHECK(parse_info(read_file(info_id))["ServiceStateNonce"] == node->service_state_nonce());
    CHECK(node->service_state_nonce() != after["ServiceStateNonce"]);
    // Without a node's nonce the listener picks a fresh one.
    const auto before_refresh = listener->service_state_nonce();
    listener->refresh_service_state();
    CHECK(listener->service_state_nonce().size() == 16);
    CHECK(listener->service_state_nonce() != before_refresh);

    // Clean close: socket and entries gone, the NodeName lock file stays (unlocked), as CORE leaves it.
    const std::string socket = listener->socket_path();
    listener->close();
    CHECK_FALSE(exists(socket));
    CHECK_FALSE(exists(info_name));
    CHECK_FALSE(exists(info_id));
    CHECK_FALSE(exists(entry_dir + "/by-nodename/" + name + ".pid"));
    CHECK(exists(tmp.dirs.user_run_dir + "/nodeids/" + name + ".pid"));
    auto gone = connect(io, "rr+local:///?nodename=" + name + "&service=svc");
    REQUIRE_FALSE(gone);
    CHECK(gone.error().type == MessageErrorType::ConnectionError);
    CHECK_THAT(gone.error().message, Catch::Contains("no local node named \"" + name + "\""));
    node->shutdown();
}

TEST_CASE("local: the NodeID cache gives a NodeName the same NodeID on every start") {
    TempNodeDirs tmp;
    const std::string name = unique_node_name("local.cache");
    NodeID first;
    std::string file;
    {
        auto r = reserve_node_name(tmp.dirs, name);
        REQUIRE(r);
        first = r->node_id;
        file = r->nodeid_file;
        CHECK_FALSE(first.is_any());
        // Root keeps it in the state dir (CORE: /var/lib/robotraconteur/nodeids), others in the config dir.
        CHECK(file == (::getuid() == 0 ? tmp.dirs.user_state_dir : tmp.dirs.user_config_dir) + "/nodeids/" + name);
        CHECK(read_file(file) == first.to_braced_string());  // "{…}", no newline, as CORE writes it
        CHECK(read_file(tmp.dirs.user_run_dir + "/nodeids/" + name + ".pid") == std::to_string(::getpid()));
        // Held: a second reservation in this process is refused.
        auto again = reserve_node_name(tmp.dirs, name);
        REQUIRE_FALSE(again);
        CHECK(again.error().type == MessageErrorType::InvalidOperation);
        CHECK_THAT(again.error().message, Catch::Contains("already in use in this process"));
    }
    auto r = reserve_node_name(tmp.dirs, name);
    REQUIRE(r);
    CHECK(r->node_id == first);

    SECTION("a configured NodeID is what a new cache entry gets, an existing entry stays") {
        const std::string other = unique_node_name("local.cache");
        const NodeID wanted = *NodeID::parse("6c3d4b2a-0f1e-4d5c-9b8a-7e6f5d4c3b2a");
        {
            auto o = reserve_node_name(tmp.dirs, other, wanted);
            REQUIRE(o);
            CHECK(o->node_id == wanted);
            CHECK(read_file(o->nodeid_file) == wanted.to_braced_string());
        }
        auto o = reserve_node_name(tmp.dirs, other, *NodeID::parse("3f2504e0-4f89-11d3-9a0c-0305e82c3301"));
        REQUIRE(o);
        CHECK(o->node_id == wanted);  // the cache wins; the caller reports a mismatch
    }
    SECTION("a cache file written by hand (any NodeID form, blanks) is used") {
        const std::string other = unique_node_name("local.cache");
        std::filesystem::create_directories(std::filesystem::path(file).parent_path());
        write_file((std::filesystem::path(file).parent_path() / other).string(), "  3F2504E0-4F89-11D3-9A0C-0305E82C3301\n");
        auto o = reserve_node_name(tmp.dirs, other);
        REQUIRE(o);
        CHECK(o->node_id.to_string() == "3f2504e0-4f89-11d3-9a0c-0305e82c3301");
    }
    SECTION("a corrupt cache file is an error naming it") {
        const std::string other = unique_node_name("local.cache");
        const std::string path = (std::filesystem::path(file).parent_path() / other).string();
        write_file(path, "not a nodeid");
        auto o = reserve_node_name(tmp.dirs, other);
        REQUIRE_FALSE(o);
        CHECK(o.error().type == MessageErrorType::IOError);
        CHECK_THAT(o.error().message, Catch::Contains(path));
    }
}

TEST_CASE("local: root reads a NodeID an administrator put in the config dir") {
    if (::getuid() != 0) RR_SKIP("needs root (the config-dir NodeID file is read only by root)");
    TempNodeDirs tmp;
    const std::string other = unique_node_name("local.cache");
    std::filesystem::create_directories(tmp.dirs.user_config_dir + "/nodeids");
    write_file(tmp.dirs.user_config_dir + "/nodeids/" + other, "{11111111-2222-3333-4444-555555555555}");
    auto o = reserve_node_name(tmp.dirs, other);
    REQUIRE(o);
    CHECK(o->node_id.to_string() == "11111111-2222-3333-4444-555555555555");
    CHECK(o->nodeid_file == tmp.dirs.user_config_dir + "/nodeids/" + other);
}

TEST_CASE("local: bad NodeNames, and a node whose NodeID is not the cached one") {
    TempNodeDirs tmp;
    for (const char* bad : {"", "9lives", "a/b", "../up", "with space"}) {
        auto r = reserve_node_name(tmp.dirs, bad);
        REQUIRE_FALSE(r);
        CHECK(r.error().type == MessageErrorType::InvalidArgument);
        CHECK_THAT(r.error().message, Catch::Contains("invalid NodeName"));
    }
    NodeOptions o;
    o.node_name = unique_node_name("local.mismatch");
    o.threads = 1;
    auto node = Node::create(o);  // random NodeID: not the one the cache will give the name
    LocalListenOptions lo;
    lo.dirs = tmp.dirs;
    auto l = listen_local(node, lo);
    REQUIRE_FALSE(l);
    CHECK(l.error().type == MessageErrorType::InvalidArgument);
    CHECK_THAT(l.error().message, Catch::Contains("create the node with the NodeID reserve_node_name() returns"));
    // Nothing left behind, the name is free again.
    CHECK_FALSE(exists(tmp.dirs.user_run_dir + "/transport/local/by-nodename/" + o.node_name + ".info"));
    CHECK(reserve_node_name(tmp.dirs, o.node_name));
    node->shutdown();
}

TEST_CASE("local: a node without NodeName is published by NodeID only") {
    TempNodeDirs tmp;
    LocalTransportFor route(tmp.dirs);
    NodeOptions o;
    o.threads = 2;
    auto node = Node::create(o);
    REQUIRE(node->register_service(std::make_shared<server::testing::RawTestService>()));
    LocalListenOptions lo;
    lo.dirs = tmp.dirs;
    auto l = listen_local(node, lo);
    REQUIRE(l);
    const std::string id = node->node_id().to_string();
    auto info = parse_info(read_file(tmp.dirs.user_run_dir + "/transport/local/by-nodeid/" + id + ".info"));
    CHECK(info["nodename"].empty());
    CHECK(std::filesystem::is_empty(tmp.dirs.user_run_dir + "/transport/local/by-nodename"));
    client::IoThreads io{1};
    auto c = connect(io, "rr+local:///?nodeid=" + id + "&service=svc");
    REQUIRE(c);
    CHECK((*c)->close_wait().ok());
    // A second listener for the same NodeID in this process is refused.
    auto second = listen_local(node, lo);
    REQUIRE_FALSE(second);
    CHECK(second.error().type == MessageErrorType::InvalidOperation);
    CHECK_THAT(second.error().message, Catch::Contains("NodeID " + id + " is already in use in this process"));
    (*l)->close();
    node->shutdown();
}

TEST_CASE("local: the service index reports rr+local:///?nodeid=…&service=… for local connections") {
    TempNodeDirs tmp;
    LocalTransportFor route(tmp.dirs);
    auto [node, listener] = start_named(tmp.dirs, unique_node_name("local.index"));
    client::IoThreads io{1};
    auto c = connect(io, "rr+local:///?nodename=" + node->node_name() + "&service=RobotRaconteurServiceIndex");
    REQUIRE(c);
    auto r = (*c)->root().call("GetLocalNodeServices");
    REQUIRE(r);
    const auto* map = r->get_if<MapInt32>();
    REQUIRE(map);
    std::vector<std::string> urls;
    for (const auto& [k, v] : map->entries) {
        const auto* s = v.get_if<Structure>();
        REQUIRE(s);
        const auto* u = s->find("ConnectionURL")->get_if<MapInt32>();
        REQUIRE(u);
        REQUIRE(u->entries.size() == 1);
        urls.push_back(*u->entries[0].second.get_if<std::string>());
    }
    const std::string base = "rr+local:///?nodeid=" + node->node_id().to_string() + "&service=";
    CHECK(urls == std::vector<std::string>{base + "RobotRaconteurServiceIndex", base + "svc"});
    // The reported URL leads to the service.
    auto direct = connect(io, base + "svc");
    REQUIRE(direct);
    CHECK((*c)->close_wait().ok());
    CHECK((*direct)->close_wait().ok());
    listener->close();
    node->shutdown();
}

TEST_CASE("local: unknown names, stale entries and mismatched entries are clear errors") {
    TempNodeDirs tmp;
    LocalTransportFor route(tmp.dirs);
    client::IoThreads io{1};
    const std::string entry_dir = tmp.dirs.user_run_dir + "/transport/local";
    std::filesystem::create_directories(entry_dir + "/by-nodename");
    std::filesystem::create_directories(entry_dir + "/by-nodeid");
    std::filesystem::create_directories(tmp.dirs.user_run_dir + "/socket");

    SECTION("no entry at all") {
        auto c = connect(io, "rr+local:///?nodename=nobody.here&service=svc");
        REQUIRE_FALSE(c);
        CHECK(c.error().type == MessageErrorType::ConnectionError);
        CHECK_THAT(c.error().message, Catch::StartsWith("no local node named \"nobody.here\" (searched " + entry_dir));
        auto d = connect(io, "rr+local:///?nodeid=11111111-2222-3333-4444-555555555555&service=svc");
        REQUIRE_FALSE(d);
        CHECK_THAT(d.error().message, Catch::StartsWith("no local node with NodeID 11111111-2222-3333-4444-555555555555"));
    }
    SECTION("stale: the socket file is gone, or nobody listens on it, and nobody holds the entry") {
        const std::string dead = tmp.dirs.user_run_dir + "/socket/deadDEADdead0000.sock";
        make_dead_socket(dead);
        write_file(entry_dir + "/by-nodename/stale.a.info", "nodename: stale.a\nsocket: " + dead + "\n");
        write_file(entry_dir + "/by-nodename/stale.b.info", "nodename: stale.b\nsocket: " + tmp.dirs.user_run_dir + "/socket/missing.sock\n");
        for (const char* n : {"stale.a", "stale.b"}) {
            auto c = connect(io, std::string("rr+local:///?nodename=") + n + "&service=svc");
            REQUIRE_FALSE(c);
            CHECK(c.error().type == MessageErrorType::ConnectionError);
            CHECK_THAT(c.error().message, Catch::StartsWith(std::string("local node named \"") + n + "\" is not running"));
            CHECK_THAT(c.error().message, Catch::Contains("stale"));
        }
    }
    SECTION("a stale private entry is skipped for a live public node of the same name") {
        const std::string name = unique_node_name("local.pub");
        const std::string dead = tmp.dirs.user_run_dir + "/socket/deadDEADdead0001.sock";
        make_dead_socket(dead);
        write_file(entry_dir + "/by-nodename/" + name + ".info", "nodename: " + name + "\nsocket: " + dead + "\n");
        // An administrator made <system run>/transport/local/<user>.
        std::filesystem::create_directories(tmp.dirs.system_run_dir + "/transport/local/" + *current_user_name());
        LocalListenOptions pub;
        pub.public_server = true;
        auto [node, listener] = start_named(tmp.dirs, name, pub);
        CHECK(listener->entry_dir() == tmp.dirs.system_run_dir + "/transport/local/" + *current_user_name());
        CHECK(listener->socket_path().rfind(listener->entry_dir() + "/socket/", 0) == 0);
        CHECK((mode_of(listener->entry_dir() + "/by-nodename") & 07777) == 02750);
        auto c = connect(io, "rr+local:///?nodename=" + name + "&service=svc");
        REQUIRE(c);
        CHECK((*c)->remote_node_id() == node->node_id());
        CHECK((*c)->close_wait().ok());
        listener->close();
        node->shutdown();
    }
    SECTION("a public node needs the administrator's directory") {
        NodeOptions o;
        o.threads = 1;
        auto node = Node::create(o);
        LocalListenOptions pub;
        pub.public_server = true;
        pub.dirs = tmp.dirs;
        auto l = listen_local(node, pub);
        REQUIRE_FALSE(l);
        CHECK(l.error().type == MessageErrorType::SystemResourceError);
        CHECK_THAT(l.error().message, Catch::Contains("not set up for public rr+local nodes"));
        node->shutdown();
    }
    SECTION("an official entry with an appended block: the last block (the live node) wins") {
        const std::string name = unique_node_name("local.append");
        auto [node, listener] = start_named(tmp.dirs, name);
        const std::string info_path = entry_dir + "/by-nodename/" + name + ".info";
        const std::string live = read_file(info_path);
        const std::string dead = tmp.dirs.user_run_dir + "/socket/deadDEADdead0002.sock";
        make_dead_socket(dead);
        // What CORE leaves after a restart: the old block first, the new one after it.
        auto old_block = parse_info(live);
        old_block["socket"] = dead;
        old_block["pid"] = "1";
        write_file(info_path, format_info(old_block) + live);
        auto c = connect(io, "rr+local:///?nodename=" + name + "&service=svc");
        REQUIRE(c);
        CHECK((*c)->close_wait().ok());
        listener->close();
        node->shutdown();
    }
    SECTION("NodeID and NodeName entries that disagree") {
        const std::string name = unique_node_name("local.mix");
        auto [node, listener] = start_named(tmp.dirs, name);
        auto c = connect(io, "rr+local:///?nodeid=" + node->node_id().to_string() + "&nodename=other.name&service=svc");
        REQUIRE_FALSE(c);
        CHECK(c.error().type == MessageErrorType::ConnectionError);
        CHECK_THAT(c.error().message, Catch::Contains("named \"" + name + "\", not \"other.name\""));
        listener->close();
        node->shutdown();
    }
    SECTION("bad URL forms") {
        for (std::string url : {"rr+local://host/?nodename=n&service=svc", "rr+local:///x/?nodename=n&service=svc",
                                "rr+local:///?service=svc", "rr+local://localhost:5/?nodename=n&service=svc"}) {
            INFO(url);
            auto c = connect(io, url);
            REQUIRE_FALSE(c);
            CHECK(c.error().type == MessageErrorType::InvalidArgument);
        }
    }
}

TEST_CASE("local: an entry this user may not read is a permission error naming it") {
    // A mode-000 directory: root reads it anyway, so root acts as nobody.
    TempNodeDirs tmp;
    const std::string by_name = tmp.dirs.user_run_dir + "/transport/local/by-nodename";
    std::filesystem::create_directories(by_name);
    write_file(by_name + "/locked.node.info", "socket: /nowhere.sock\n");
    for (const auto& d : {tmp.dirs.user_run_dir, tmp.dirs.user_run_dir + "/transport", tmp.dirs.user_run_dir + "/transport/local"})
        ::chmod(d.c_str(), 0755);
    ::chmod(by_name.c_str(), 0);
    client::IoThreads io{1};
    const auto url = *parse_connection_url("rr+local:///?nodename=locked.node&service=svc");
    Result<boost::asio::local::stream_protocol::socket> s = fail(MessageErrorType::None, "");
    if (::geteuid() == 0) as_nobody([&] { s = connect_local_socket(io.executor(), url, tmp.dirs); });
    else s = connect_local_socket(io.executor(), url, tmp.dirs);
    ::chmod(by_name.c_str(), 0755);
    REQUIRE_FALSE(s);
    CHECK(s.error().type == MessageErrorType::ConnectionError);
    CHECK_THAT(s.error().message, Catch::Contains("permission denied reading " + by_name + "/locked.node.info"));
}

TEST_CASE("local: the socket of another user's node is a permission error, its own user connects") {
    if (::getuid() != 0 && ::geteuid() != 0) RR_SKIP("needs root (to act as another user)");
    TempNodeDirs tmp;
    const std::string name = unique_node_name("local.perm");
    auto [node, listener] = start_named(tmp.dirs, name);
    const std::string entry_dir = tmp.dirs.user_run_dir + "/transport/local";
    const std::string info = entry_dir + "/by-nodename/" + name + ".info";
    for (const auto& d : {tmp.dirs.user_run_dir, tmp.dirs.user_run_dir + "/transport", entry_dir, entry_dir + "/by-nodename",
                          tmp.dirs.user_run_dir + "/socket"})
        ::chmod(d.c_str(), 0755);
    client::IoThreads io{1};
    auto url = *parse_connection_url("rr+local:///?nodename=" + name + "&service=svc");

    SECTION("the entry is readable, the socket (0770, another user's) is not") {
        ::chmod(info.c_str(), 0644);
        Result<boost::asio::local::stream_protocol::socket> s = fail(MessageErrorType::None, "");
        as_nobody([&] { s = connect_local_socket(io.executor(), url, tmp.dirs); });
        REQUIRE_FALSE(s);
        CHECK(s.error().type == MessageErrorType::ConnectionError);
        CHECK_THAT(s.error().message, Catch::Contains("permission denied connecting to " + listener->socket_path()));
    }
    SECTION("as the node's own user it connects") {
        auto s = connect_local_socket(io.executor(), url, tmp.dirs);
        REQUIRE(s);
    }
    listener->close();
    node->shutdown();
}

TEST_CASE("local: a run directory this user may not write is a permission error naming it") {
    if (::getuid() != 0 && ::geteuid() != 0) RR_SKIP("needs root (to act as another user on a directory root owns)");
    TempNodeDirs tmp;  // root-owned, mode 0755: another user may read but not write
    const std::string name = unique_node_name("local.nowrite");
    auto r = reserve_node_name(tmp.dirs, name);
    REQUIRE(r);
    NodeOptions o;
    o.node_id = r->node_id;
    o.node_name = name;
    o.threads = 1;
    auto node = Node::create(o);
    LocalListenOptions opts;
    opts.dirs = tmp.dirs;
    Result<std::shared_ptr<LocalListener>> l = fail(MessageErrorType::None, "");
    as_nobody([&] { l = listen_local(node, opts, std::move(*r)); });
    REQUIRE_FALSE(l);
    CHECK(l.error().type == MessageErrorType::SystemResourcePermissionDenied);
    CHECK_THAT(l.error().message, Catch::Contains(tmp.root));
    node->shutdown();
}

TEST_CASE("local: a NodeName held by another process is refused, and free again when it exits") {
    // The other process: Python's fcntl.lockf takes the same kind of lock CORE takes (fcntl F_SETLK).
    if (::access("/usr/bin/python3", X_OK) != 0) RR_SKIP("/usr/bin/python3 is needed to hold a lock from another process");
    TempNodeDirs tmp;
    const std::string name = unique_node_name("local.taken");
    const std::string lock_path = tmp.dirs.user_run_dir + "/nodeids/" + name + ".pid";
    std::filesystem::create_directories(tmp.dirs.user_run_dir + "/nodeids");
    const std::string script = "import fcntl,os,sys,time\nf=open(sys.argv[1],'a+')\nfcntl.lockf(f,fcntl.LOCK_EX|fcntl.LOCK_NB)\n"
                               "f.write(str(os.getpid()));f.flush()\ntime.sleep(300)\n";  // killed below
    const char* argv[] = {"/usr/bin/python3", "-c", script.c_str(), lock_path.c_str(), nullptr};
    pid_t child = 0;
    REQUIRE(::posix_spawn(&child, argv[0], nullptr, nullptr, const_cast<char* const*>(argv), environ) == 0);
    struct Reaper {  // a failed REQUIRE must not leave the child holding ctest's output pipe
        pid_t& pid;
        ~Reaper() {
            if (pid <= 0) return;
            ::kill(pid, SIGKILL);
            int st = 0;
            ::waitpid(pid, &st, 0);
        }
    } reaper{child};
    REQUIRE(eventually([&] { return lock_holder(lock_path).has_value(); }));  // Python started (slow under load)
    REQUIRE(lock_holder(lock_path) == child);

    auto r = reserve_node_name(tmp.dirs, name);
    REQUIRE_FALSE(r);
    CHECK(r.error().type == MessageErrorType::InvalidOperation);
    CHECK(r.error().message == "NodeName \"" + name + "\" is already in use by process " + std::to_string(child) + " (lock " +
                                   lock_path + ")");

    const pid_t holder = child;
    child = 0;
    ::kill(holder, SIGKILL);
    int status = 0;
    ::waitpid(holder, &status, 0);
    auto again = reserve_node_name(tmp.dirs, name);
    REQUIRE(again);
}

TEST_CASE("local: RawClient (the gateway's device client) and default_node_directories() honour the overrides") {
    // The environment is read at each connect: point this process's node directories at a temp tree.
    TempNodeDirs tmp;
    struct Env {
        std::vector<std::pair<std::string, std::optional<std::string>>> saved;
        void set(const char* k, const std::string& v) {
            const char* old = std::getenv(k);
            saved.emplace_back(k, old ? std::optional<std::string>(old) : std::nullopt);
            ::setenv(k, v.c_str(), 1);
        }
        ~Env() {
            for (auto& [k, v] : saved)
                if (v) ::setenv(k.c_str(), v->c_str(), 1);
                else ::unsetenv(k.c_str());
        }
    } env;
    NodeDirectories expect;
    if (::getuid() == 0) {
        env.set("ROBOTRACONTEUR_SYSTEM_RUN_DIR", tmp.root + "/sysrun");
        env.set("ROBOTRACONTEUR_SYSTEM_STATE_DIR", tmp.root + "/sysstate");
        env.set("ROBOTRACONTEUR_SYSTEM_CONFIG_DIR", tmp.root + "/sysconfig");
        CHECK(default_node_directories().user_run_dir == tmp.root + "/sysrun/root");
    } else {
        env.set("ROBOTRACONTEUR_USER_RUN_DIR", tmp.root + "/run");
        env.set("ROBOTRACONTEUR_USER_CONFIG_DIR", tmp.root + "/config");
        env.set("ROBOTRACONTEUR_SYSTEM_RUN_DIR", tmp.root + "/sysrun");
        CHECK(default_node_directories().user_run_dir == tmp.root + "/run");
    }
    const NodeDirectories dirs = default_node_directories();
    auto [node, listener] = start_named(dirs, unique_node_name("local.raw"));
    client::IoThreads io{1};

    auto url = parse_connection_url("rr+local:///?nodename=" + node->node_name() + "&service=svc");
    REQUIRE(url);
    std::promise<Result<std::shared_ptr<RawClient>>> p;
    RawClient::connect(io.executor(), *url, {}, {}, {}, [&](Result<std::shared_ptr<RawClient>> r) { p.set_value(std::move(r)); });
    auto raw = p.get_future().get();
    REQUIRE(raw);
    CHECK((*raw)->remote_node_id() == node->node_id());
    MessageEntry get;
    get.entry_type = MessageEntryType::PropertyGetReq;
    get.service_path = "svc";
    get.member_name = "x";
    std::promise<Result<MessageEntry>> reply;
    (*raw)->request(std::move(get), [&](Result<MessageEntry> r) { reply.set_value(std::move(r)); });
    auto e = reply.get_future().get();
    REQUIRE(e);
    CHECK(e->error == MessageErrorType::None);
    (*raw)->close();

    // And the typed client's built-in rr+local (no LocalTransportFor here).
    auto c = Client::connect(io.executor(), "rr+local:///?nodeid=" + node->node_id().to_string() + "&service=svc");
    REQUIRE(c);
    CHECK((*c)->close_wait().ok());

    auto missing = parse_connection_url("rr+local:///?nodename=not.there&service=svc");
    std::promise<Result<std::shared_ptr<RawClient>>> q;
    RawClient::connect(io.executor(), *missing, {}, {}, {}, [&](Result<std::shared_ptr<RawClient>> r) { q.set_value(std::move(r)); });
    auto none = q.get_future().get();
    REQUIRE_FALSE(none);
    CHECK_THAT(none.error().message, Catch::Contains("no local node named \"not.there\""));
    listener->close();
    node->shutdown();
}
