// Local node discovery (local_discovery.hpp) in temporary node directories: what CORE's
// FindNodesInDirectory reports (URLs, NodeName, nonce, public user directories), that only running nodes
// count, and that the watcher follows servers starting and stopping.
#include <catch2/catch.hpp>

#include <atomic>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <future>
#include <mutex>
#include <set>
#include <thread>

#include <sys/wait.h>
#include <unistd.h>

#include "server/client/client.hpp"
#include "server/node/node.hpp"
#include "server/transport/local/local_connector.hpp"
#include "server/transport/local/local_discovery.hpp"
#include "server/transport/local/local_entries.hpp"
#include "server/transport/local/local_layout.hpp"
#include "server/transport/local/local_listener.hpp"
#include "server/transport/local/local_test_support.hpp"
#include "test/support/eventually.hpp"

using namespace rr;
using namespace rr::server;
using namespace rr::server::local;
using namespace rr::server::local::testing;
using namespace std::chrono_literals;

namespace {

using rr::testing::eventually;

void write_entry_file(const std::string& path, const std::string& text) {
    std::filesystem::create_directories(std::filesystem::path(path).parent_path());
    std::ofstream f(path, std::ios::binary | std::ios::trunc);
    f << text;
    REQUIRE(f.good());
}

std::string info_text(const NodeID& id, const std::string& name, const std::string& user, const std::string& nonce,
                      int pid = 99999) {
    InfoMap m;
    m["nodeid"] = id.to_braced_string();
    m["nodename"] = name;
    m["username"] = user;
    m["ServiceStateNonce"] = nonce;
    m["pid"] = std::to_string(pid);
    m["socket"] = "/nonexistent.sock";
    return format_info(m);
}

/// Another process that holds fcntl write locks on `paths` (as a running server holds its entries)
/// until destroyed.
class LockHolder {
public:
    explicit LockHolder(const std::vector<std::string>& paths) {
        int ready[2], quit[2];
        REQUIRE(::pipe(ready) == 0);
        REQUIRE(::pipe(quit) == 0);
        std::vector<const char*> c_paths;
        for (const auto& p : paths) c_paths.push_back(p.c_str());
        pid_ = ::fork();
        REQUIRE(pid_ >= 0);
        if (pid_ == 0) {  // only async-signal-safe calls from here
            ::close(ready[0]);
            ::close(quit[1]);
            for (const char* p : c_paths) {
                const int fd = ::open(p, O_RDWR);
                struct flock l {};
                l.l_type = F_WRLCK;
                l.l_whence = SEEK_SET;
                if (fd < 0 || ::fcntl(fd, F_SETLK, &l) != 0) ::_exit(2);
            }
            char b = 1;
            (void)::write(ready[1], &b, 1);
            (void)::read(quit[0], &b, 1);  // until the parent closes its end
            ::_exit(0);
        }
        ::close(ready[1]);
        ::close(quit[0]);
        quit_ = quit[1];
        char b = 0;
        REQUIRE(::read(ready[0], &b, 1) == 1);
        ::close(ready[0]);
    }
    ~LockHolder() { release(); }
    void release() {
        if (pid_ <= 0) return;
        ::close(quit_);
        int status = 0;
        ::waitpid(pid_, &status, 0);
        pid_ = -1;
    }
    pid_t pid() const { return pid_; }

private:
    pid_t pid_ = -1;
    int quit_ = -1;
};

struct Served {
    std::shared_ptr<Node> node;
    std::shared_ptr<LocalListener> listener;
};

Served serve(const NodeDirectories& dirs, const std::string& name) {
    auto r = reserve_node_name(dirs, name);
    REQUIRE(r);
    NodeOptions o;
    o.node_id = r->node_id;
    o.node_name = name;
    o.threads = 1;
    auto node = Node::create(o);
    LocalListenOptions lo;
    lo.dirs = dirs;
    auto l = listen_local(node, lo, std::move(*r));
    REQUIRE(l);
    return {node, *l};
}

}  // namespace

TEST_CASE("local discovery: a running node is found with CORE's URL, its NodeName and its nonce") {
    TempNodeDirs tmp;
    const std::string name = unique_node_name("disc.basic");
    auto s = serve(tmp.dirs, name);
    const auto id = s.node->node_id();

    // A node of this very process is left out unless asked for (a gateway must not find itself).
    CHECK(find_local_nodes(tmp.dirs).empty());
    LocalScanOptions own;
    own.include_own_process = true;
    auto found = find_local_nodes(tmp.dirs, own);
    REQUIRE(found.size() == 1);
    CHECK(found[0].node_id == id);
    CHECK(found[0].node_name == name);
    CHECK(found[0].urls == std::vector<std::string>{"rr+local:///?nodeid=" + id.to_string() + "&service=RobotRaconteurServiceIndex"});
    CHECK(found[0].service_state_nonce == s.node->service_state_nonce());
    CHECK(found[0].pid == ::getpid());
    CHECK(found[0].user == *current_user_name());

    // The URL reaches the node's service index over rr+local.
    // (an rr+local connector that searches the test's node directories, not this process's)
    client::IoThreads io(1);
    server::TransportRegistry transports;
    transports.add("rr+local", std::make_shared<server::local::LocalConnector>([d = tmp.dirs] { return d; }));
    client::ClientOptions co;
    co.transports = &transports;
    auto c = client::Client::connect(io.executor(), found[0].urls[0], co);
    REQUIRE(c);
    CHECK((*c)->remote_node_id() == id);
    (void)(*c)->close_wait();

    // Closed: the entries go, and so does the node.
    s.listener->close();
    CHECK(find_local_nodes(tmp.dirs, own).empty());
    s.node->shutdown();
}

TEST_CASE("local discovery: only entries a running process holds count, malformed ones are skipped") {
    TempNodeDirs tmp;
    const std::string dir = tmp.dirs.user_run_dir + "/transport/local";
    const std::string user = *current_user_name();
    const auto live = NodeID::parse("{11111111-2222-4333-8444-555555555555}").value();
    const auto stale = NodeID::parse("{21111111-2222-4333-8444-555555555555}").value();
    const std::string live_info = by_nodeid_file(dir, live, "info");
    write_entry_file(live_info, info_text(live, "", user, "NonceA"));
    write_entry_file(by_nodeid_file(dir, stale, "info"), info_text(stale, "stale.node", user, "NonceB"));  // nobody holds it
    write_entry_file(dir + "/by-nodeid/garbage.info", "no keys here\n");
    write_entry_file(dir + "/by-nodeid/noid.info", "username: " + user + "\n");
    write_entry_file(dir + "/by-nodeid/badid.info", "nodeid: {nope}\nusername: " + user + "\n");
    write_entry_file(dir + "/by-nodeid/huge.info", std::string(kMaxEntryFileSize + 10, 'x'));
    write_entry_file(dir + "/by-nodeid/" + live.to_string() + ".pid", "99999");  // not an .info: ignored
    // The NodeName comes from by-nodename/<name>.info naming the NodeID (CORE), not from a file whose
    // name and content disagree.
    write_entry_file(dir + "/by-nodename/live.node.info", info_text(live, "live.node", user, "NonceA"));
    write_entry_file(dir + "/by-nodename/liar.info", info_text(live, "other.name", user, "NonceA"));

    CHECK(find_local_nodes(tmp.dirs).empty());  // nobody holds any entry
    {
        LockHolder holder({live_info});
        auto found = find_local_nodes(tmp.dirs);
        REQUIRE(found.size() == 1);
        CHECK(found[0].node_id == live);
        CHECK(found[0].node_name == "live.node");
        CHECK(found[0].service_state_nonce == "NonceA");
        CHECK(found[0].urls == std::vector<std::string>{"rr+local:///?nodeid=" + live.to_string() + "&service=RobotRaconteurServiceIndex"});
        holder.release();  // the process ended (a killed server's locks go the same way)
        CHECK(find_local_nodes(tmp.dirs).empty());
    }
}

TEST_CASE("local discovery: public user directories give user@localhost URLs") {
    TempNodeDirs tmp;
    const auto id = NodeID::parse("{31111111-2222-4333-8444-555555555555}").value();
    const auto other = NodeID::parse("{41111111-2222-4333-8444-555555555555}").value();
    const std::string ann = tmp.dirs.system_run_dir + "/transport/local/ann";
    const std::string info = by_nodeid_file(ann, id, "info");
    const std::string wrong_user = by_nodeid_file(ann, other, "info");
    write_entry_file(info, info_text(id, "pub.node", "ann", "NonceP"));
    write_entry_file(wrong_user, info_text(other, "", "bob", "NonceQ"));  // in ann's directory but bob's: skipped
    write_entry_file(tmp.dirs.system_run_dir + "/transport/local/bad user/by-nodeid/x.info", "");  // not a user name
    LockHolder holder({info, wrong_user});
    auto found = find_local_nodes(tmp.dirs);
    REQUIRE(found.size() == 1);
    CHECK(found[0].node_id == id);
    CHECK(found[0].user == "ann");
    CHECK(found[0].urls ==
          std::vector<std::string>{"rr+local://ann@localhost/?nodeid=" + id.to_string() + "&service=RobotRaconteurServiceIndex"});
    // The URL parses as an rr+local URL of that user.
    auto u = parse_connection_url(found[0].urls[0]);
    REQUIRE(u);
    auto t = local_target(*u);
    REQUIRE(t);
    CHECK(t->user == "ann");
}

TEST_CASE("local discovery: the watcher follows servers starting and stopping") {
    for (const bool inotify : {true, false}) {
        INFO("inotify " << inotify);
        TempNodeDirs tmp;
        client::IoThreads io(1);
        std::mutex m;
        std::vector<NodeID> seen, lost;
        LocalWatchOptions o;
        o.scan.include_own_process = true;
        o.use_inotify = inotify;
        o.poll_interval = inotify ? 0ms : 100ms;  // with inotify, events alone must do it (no polling)
        auto w = LocalNodeWatcher::create(io.executor(), tmp.dirs, o,
                                          [&](const std::vector<LocalNodeInfo>& f, const std::vector<LocalNodeInfo>& l) {
                                              std::lock_guard lock(m);
                                              for (const auto& n : f) seen.push_back(n.node_id);
                                              for (const auto& n : l) lost.push_back(n.node_id);
                                          });
        std::promise<void> started;
        w->start([&] { started.set_value(); });
        REQUIRE(started.get_future().wait_for(30s) == std::future_status::ready);
        CHECK(w->uses_inotify() == inotify);
        // The directories do not exist yet: the first server creates them.
        CHECK_FALSE(std::filesystem::exists(tmp.dirs.user_run_dir + "/transport"));
        auto s = serve(tmp.dirs, unique_node_name("disc.watch"));
        const auto id = s.node->node_id();
        CHECK(eventually([&] {
            std::lock_guard lock(m);
            return std::find(seen.begin(), seen.end(), id) != seen.end();
        }));
        REQUIRE(w->nodes().size() == 1);
        CHECK(w->nodes()[0].node_name == s.node->node_name());
        s.listener->close();
        CHECK(eventually([&] {
            std::lock_guard lock(m);
            return std::find(lost.begin(), lost.end(), id) != lost.end();
        }));
        CHECK(w->nodes().empty());
        w->stop();
        s.node->shutdown();
    }
}

// The race a watcher must not lose: entry directories created while it looks for them and adds its
// watches. Each round starts a watcher (events only, no polling) while another thread creates the
// directory tree level by level, then publishes an entry a process holds; the node must be found, and
// lost once its entry goes, every round.
TEST_CASE("local discovery: directories created while the watcher starts are watched") {
    constexpr int kRounds = 30;
    int missed_found = 0, missed_lost = 0;
    for (int round = 0; round < kRounds; ++round) {
        TempNodeDirs tmp;
        client::IoThreads io(1);
        std::mutex m;
        std::set<NodeID> seen, lost;
        LocalWatchOptions o;
        o.poll_interval = 0ms;
        o.debounce = 5ms;
        auto w = LocalNodeWatcher::create(io.executor(), tmp.dirs, o,
                                          [&](const std::vector<LocalNodeInfo>& f, const std::vector<LocalNodeInfo>& l) {
                                              std::lock_guard lock(m);
                                              for (const auto& n : f) seen.insert(n.node_id);
                                              for (const auto& n : l) lost.insert(n.node_id);
                                          });
        const auto id = NodeID::parse("{51111111-2222-4333-8444-555555555555}").value();
        const std::string dir = tmp.dirs.user_run_dir + "/transport/local";
        const std::string info = by_nodeid_file(dir, id, "info");
        std::thread maker([&] {
            // One level at a time, so that each level may appear between a look and a watch.
            for (const std::string& d : {tmp.dirs.user_run_dir, tmp.dirs.user_run_dir + "/transport", dir, dir + "/by-nodeid"})
                std::filesystem::create_directory(d);
        });
        w->start();
        maker.join();
        // Published as a server would be seen by a watcher that missed nothing: the entry, already
        // held, moved into by-nodeid (a lock itself sends no inotify event).
        const std::string staged = tmp.root + "/staged.info";
        write_entry_file(staged, info_text(id, "race.node", *current_user_name(), "N"));
        LockHolder holder({staged});
        std::filesystem::rename(staged, info);
        if (!eventually([&] {
                std::lock_guard lock(m);
                return seen.count(id) == 1;
            }))
            ++missed_found;
        holder.release();
        std::filesystem::remove(info);  // what a stopping server does
        if (!eventually([&] {
                std::lock_guard lock(m);
                return lost.count(id) == 1;
            }))
            ++missed_lost;
        w->stop();
    }
    CHECK(missed_found == 0);
    CHECK(missed_lost == 0);
}
