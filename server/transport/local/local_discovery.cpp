#include "server/transport/local/local_discovery.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <set>

#include <sys/inotify.h>
#include <unistd.h>

#include <boost/asio/bind_executor.hpp>
#include <boost/asio/dispatch.hpp>
#include <boost/asio/posix/stream_descriptor.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>

#include "server/transport/local/local_entries.hpp"
#include "server/transport/local/local_layout.hpp"

namespace rr::server::local {

namespace asio = boost::asio;
namespace fs = std::filesystem;

namespace {

constexpr std::string_view kServiceIndexQuery = "&service=RobotRaconteurServiceIndex";

// The `.info` files of one directory (regular files ending in ".info"), at most `max`, sorted.
std::vector<fs::path> info_files(const fs::path& dir, std::size_t max) {
    std::vector<fs::path> out;
    std::error_code ec;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
        if (out.size() >= max) break;
        const auto& p = it->path();
        if (p.extension() != ".info") continue;
        std::error_code sec;
        if (!it->is_regular_file(sec)) continue;
        out.push_back(p);
    }
    std::sort(out.begin(), out.end());
    return out;
}

bool entry_is_live(const std::string& info_path, const InfoMap& info, bool& own_process) {
    own_process = false;
    int pid = 0;
    if (auto p = info.find("pid"); p != info.end()) pid = std::atoi(p->second.c_str());
    if (pid > 0 && pid == static_cast<int>(::getpid())) {
        own_process = true;
        auto s = info.find("socket");
        std::error_code ec;
        return s != info.end() && fs::exists(s->second, ec);
    }
    // A running server (the official one and ours) holds an fcntl write lock on the `.pid` file next to
    // its `.info` entry (by-nodeid/<id>.pid); an entry locked itself counts too.
    const auto dot = info_path.rfind(".info");
    if (dot != std::string::npos && lock_holder(info_path.substr(0, dot) + ".pid").has_value()) return true;
    return lock_holder(info_path).has_value();
}

// One entry directory (CORE FindNodesInDirectory). `user`: the public directory's user ("" = private).
void scan_dir(const std::string& dir, const std::string& user, const LocalScanOptions& options,
              std::map<NodeID, LocalNodeInfo>& out) {
    std::map<NodeID, LocalNodeInfo> here;
    for (const auto& path : info_files(fs::path(dir) / "by-nodeid", options.max_entries_per_dir)) {
        auto text = read_small_file(path.string(), kMaxEntryFileSize);
        if (!text) continue;
        const InfoMap info = parse_info(*text);
        auto id_it = info.find("nodeid");
        auto user_it = info.find("username");
        if (id_it == info.end() || user_it == info.end()) continue;
        auto id = NodeID::parse(id_it->second);
        if (!id || id->is_any()) continue;
        if (!user.empty() && user_it->second != user) continue;
        bool own = false;
        if (!entry_is_live(path.string(), info, own)) continue;
        if (own && !options.include_own_process) continue;
        LocalNodeInfo n;
        n.node_id = *id;
        n.user = user_it->second;
        if (auto p = info.find("pid"); p != info.end()) n.pid = std::atoi(p->second.c_str());
        if (auto s = info.find("ServiceStateNonce"); s != info.end()) n.service_state_nonce = s->second;
        if (auto nm = info.find("nodename"); nm != info.end() && is_valid_node_name(nm->second)) n.node_name = nm->second;
        n.urls.push_back((user.empty() ? std::string("rr+local:///?nodeid=") : "rr+local://" + user + "@localhost/?nodeid=") +
                         id->to_string() + std::string(kServiceIndexQuery));
        here[*id] = std::move(n);
    }
    // NodeNames as CORE takes them: by-nodename/<N>.info whose nodename is N, matched by NodeID.
    if (!here.empty()) {
        for (const auto& path : info_files(fs::path(dir) / "by-nodename", options.max_entries_per_dir)) {
            auto text = read_small_file(path.string(), kMaxEntryFileSize);
            if (!text) continue;
            const InfoMap info = parse_info(*text);
            auto id_it = info.find("nodeid");
            auto name_it = info.find("nodename");
            if (id_it == info.end() || name_it == info.end()) continue;
            if (name_it->second != path.stem().string() || !is_valid_node_name(name_it->second)) continue;
            auto id = NodeID::parse(id_it->second);
            if (!id) continue;
            if (auto n = here.find(*id); n != here.end()) n->second.node_name = name_it->second;
        }
    }
    for (auto& [id, n] : here) {
        auto it = out.find(id);
        if (it == out.end()) {
            out.emplace(id, std::move(n));
            continue;
        }
        for (auto& u : n.urls) it->second.urls.push_back(std::move(u));
        if (it->second.node_name.empty()) it->second.node_name = n.node_name;
    }
}

// The directories a scan reads: the private entry dir, then each public user dir (user name, path).
std::vector<std::pair<std::string, std::string>> scan_dirs(const NodeDirectories& dirs, std::size_t max_users) {
    std::vector<std::pair<std::string, std::string>> out;
    out.emplace_back("", private_entry_dir(dirs));
    std::vector<std::pair<std::string, std::string>> pub;
    std::error_code ec;
    for (fs::directory_iterator it(public_search_dir(dirs), ec), end; !ec && it != end; it.increment(ec)) {
        if (pub.size() >= max_users) break;
        std::error_code dec;
        if (!it->is_directory(dec)) continue;
        const auto user = it->path().filename().string();
        if (!is_valid_local_username(user)) continue;
        pub.emplace_back(user, it->path().string());
    }
    std::sort(pub.begin(), pub.end());
    out.insert(out.end(), pub.begin(), pub.end());
    return out;
}

}  // namespace

std::vector<LocalNodeInfo> find_local_nodes(const NodeDirectories& dirs, const LocalScanOptions& options) {
    std::map<NodeID, LocalNodeInfo> all;
    for (const auto& [user, dir] : scan_dirs(dirs, options.max_public_users)) scan_dir(dir, user, options, all);
    std::vector<LocalNodeInfo> out;
    out.reserve(all.size());
    for (auto& [id, n] : all) out.push_back(std::move(n));
    return out;
}

// --- LocalNodeWatcher ------------------------------------------------------------------------------

class LocalNodeWatcher::Impl : public std::enable_shared_from_this<LocalNodeWatcher::Impl> {
public:
    Impl(asio::any_io_executor ex, NodeDirectories dirs, LocalWatchOptions options, Listener listener)
        : strand_(asio::make_strand(ex)), dirs_(std::move(dirs)), options_(std::move(options)), listener_(std::move(listener)),
          poll_timer_(strand_), debounce_timer_(strand_), notify_(strand_) {}

    void start(std::function<void()> on_started) {
        asio::dispatch(strand_, [self = shared_from_this(), on_started = std::move(on_started)] {
            if (self->started_ || self->stopped_) return;
            self->started_ = true;
            if (self->options_.use_inotify) {
                const int fd = ::inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
                if (fd >= 0) {
                    boost::system::error_code ec;
                    self->notify_.assign(fd, ec);
                    if (ec) ::close(fd);
                }
            }
            self->scan();
            self->wait_events();
            self->arm_poll();
            if (on_started) on_started();
        });
    }

    void stop() {
        {
            std::lock_guard lock(mutex_);
            listener_stopped_ = true;
        }
        asio::dispatch(strand_, [self = shared_from_this()] {
            if (self->stopped_) return;
            self->stopped_ = true;
            self->poll_timer_.cancel();
            self->debounce_timer_.cancel();
            boost::system::error_code ec;
            self->notify_.close(ec);
            self->watches_.clear();
        });
    }

    void rescan() {
        asio::post(strand_, [self = shared_from_this()] {
            if (!self->stopped_ && self->started_) self->scan();
        });
    }

    std::vector<LocalNodeInfo> nodes() const {
        std::lock_guard lock(mutex_);
        std::vector<LocalNodeInfo> out;
        for (const auto& [id, n] : last_) out.push_back(n);
        return out;
    }

    bool uses_inotify() const {
        std::lock_guard lock(mutex_);
        return inotify_;
    }

private:
    // strand only
    void scan() {
        update_watches();
        auto found = find_local_nodes(dirs_, options_.scan);
        std::map<NodeID, LocalNodeInfo> now;
        for (auto& n : found) now.emplace(n.node_id, n);
        std::vector<LocalNodeInfo> lost;
        Listener listener;
        {
            std::lock_guard lock(mutex_);
            for (const auto& [id, n] : last_)
                if (!now.count(id)) lost.push_back(n);
            last_ = std::move(now);
            if (!listener_stopped_) listener = listener_;
        }
        if (listener) listener(found, lost);
    }

    // The directories to watch: each entry directory, or while it does not exist its nearest existing
    // ancestor (whose IN_CREATE starts a rescan that watches the directory once it is there).
    std::set<std::string> wanted_watches() const {
        std::vector<std::string> want;
        for (const auto& [user, dir] : scan_dirs(dirs_, options_.scan.max_public_users)) {
            want.push_back(dir);
            want.push_back(dir + "/by-nodeid");
            want.push_back(dir + "/by-nodename");
        }
        want.push_back(public_search_dir(dirs_));
        std::set<std::string> wanted;
        for (const auto& dir : want) {
            std::error_code ec;
            fs::path p(dir);
            while (!p.empty() && !fs::is_directory(p, ec) && p.has_relative_path()) p = p.parent_path();
            if (!p.empty() && fs::is_directory(p, ec)) wanted.insert(p.string());
        }
        return wanted;
    }

    // Watches the entry directories that exist now. A directory created after wanted_watches() looked
    // and before its parent's watch was added sends no event: so after adding watches, look again, until
    // a look adds none (then every directory made since is announced by a watch already in place).
    void update_watches() {
        if (!notify_.is_open()) return;
        constexpr std::uint32_t kMask = IN_CREATE | IN_DELETE | IN_MODIFY | IN_ATTRIB | IN_CLOSE_WRITE | IN_MOVED_FROM |
                                        IN_MOVED_TO | IN_DELETE_SELF | IN_ONLYDIR;
        // Each round that adds a watch found a directory one level deeper; the paths are a few levels deep.
        constexpr int kMaxRounds = 16;
        bool settled = false;
        for (int round = 0; round < kMaxRounds && !settled; ++round) {
            const auto wanted = wanted_watches();
            for (auto it = watches_.begin(); it != watches_.end();) {
                if (!wanted.count(it->first)) {
                    ::inotify_rm_watch(notify_.native_handle(), it->second);
                    it = watches_.erase(it);
                } else {
                    ++it;
                }
            }
            settled = true;
            for (const auto& dir : wanted) {
                if (dir.empty() || watches_.count(dir)) continue;
                const int wd = ::inotify_add_watch(notify_.native_handle(), dir.c_str(), kMask);
                if (wd >= 0) {
                    watches_[dir] = wd;
                    settled = false;
                }
            }
        }
        // Directories kept changing under every look: look again after the debounce.
        if (!settled) schedule_scan();
        std::lock_guard lock(mutex_);
        inotify_ = true;
    }

    void wait_events() {
        if (!notify_.is_open()) return;
        notify_.async_wait(asio::posix::stream_descriptor::wait_read,
                           asio::bind_executor(strand_, [self = shared_from_this()](boost::system::error_code ec) {
                               if (ec || self->stopped_) return;
                               self->drain_events();
                               self->wait_events();
                           }));
    }

    void drain_events() {
        alignas(inotify_event) std::array<char, 4096> buf;
        bool any = false;
        for (;;) {
            const ssize_t n = ::read(notify_.native_handle(), buf.data(), buf.size());
            if (n <= 0) break;
            any = true;
            for (ssize_t off = 0; off + static_cast<ssize_t>(sizeof(inotify_event)) <= n;) {
                inotify_event ev{};
                std::memcpy(&ev, buf.data() + off, sizeof ev);
                if (ev.mask & (IN_DELETE_SELF | IN_IGNORED))
                    for (auto it = watches_.begin(); it != watches_.end(); ++it)
                        if (it->second == ev.wd) {
                            watches_.erase(it);
                            break;
                        }
                off += static_cast<ssize_t>(sizeof(inotify_event) + ev.len);
            }
        }
        if (any) schedule_scan();
    }

    // A scan after the debounce (a starting server writes several files), unless one is pending.
    void schedule_scan() {
        if (debounce_pending_ || stopped_) return;
        debounce_pending_ = true;
        debounce_timer_.expires_after(options_.debounce);
        debounce_timer_.async_wait(asio::bind_executor(strand_, [self = shared_from_this()](boost::system::error_code ec) {
            self->debounce_pending_ = false;
            if (ec || self->stopped_) return;
            self->scan();
        }));
    }

    void arm_poll() {
        if (stopped_ || options_.poll_interval.count() <= 0) return;
        poll_timer_.expires_after(options_.poll_interval);
        poll_timer_.async_wait(asio::bind_executor(strand_, [self = shared_from_this()](boost::system::error_code ec) {
            if (ec || self->stopped_) return;
            self->scan();
            self->arm_poll();
        }));
    }

    asio::strand<asio::any_io_executor> strand_;
    NodeDirectories dirs_;
    LocalWatchOptions options_;
    Listener listener_;
    asio::steady_timer poll_timer_, debounce_timer_;
    asio::posix::stream_descriptor notify_;
    std::map<std::string, int> watches_;
    bool started_ = false, stopped_ = false, debounce_pending_ = false;

    mutable std::mutex mutex_;
    std::map<NodeID, LocalNodeInfo> last_;
    bool listener_stopped_ = false;
    bool inotify_ = false;
};

std::shared_ptr<LocalNodeWatcher> LocalNodeWatcher::create(asio::any_io_executor executor, NodeDirectories dirs,
                                                           LocalWatchOptions options, Listener listener) {
    return std::shared_ptr<LocalNodeWatcher>(
        new LocalNodeWatcher(std::make_shared<Impl>(std::move(executor), std::move(dirs), std::move(options), std::move(listener))));
}

LocalNodeWatcher::~LocalNodeWatcher() { stop(); }

void LocalNodeWatcher::start(std::function<void()> on_started) { impl_->start(std::move(on_started)); }
void LocalNodeWatcher::stop() {
    if (impl_) impl_->stop();
}
void LocalNodeWatcher::rescan() { impl_->rescan(); }
std::vector<LocalNodeInfo> LocalNodeWatcher::nodes() const { return impl_->nodes(); }
bool LocalNodeWatcher::uses_inotify() const { return impl_->uses_inotify(); }

}  // namespace rr::server::local
