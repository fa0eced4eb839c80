// Local node discovery (CORE LocalTransport.cpp FindNodesInDirectory / LocalTransportDiscovery::Refresh,
// LocalTransport_linux.cpp LinuxLocalTransportDiscovery): the rr+local nodes of this computer, found in
// the entry directories that rr+local servers publish (docs/local-transport.md, "Files").
//
// Where (CORE's order): the private entry dir `<user run>/transport/local`, then every user directory
// below the public search dir `<system run>/transport/local/<user>/`. In each, every
// `by-nodeid/<nodeid>.info` that names `nodeid` and `username` is a node:
//   private:  rr+local:///?nodeid=<8-4-4-4-12>&service=RobotRaconteurServiceIndex
//   public:   rr+local://<user>@localhost/?nodeid=<8-4-4-4-12>&service=RobotRaconteurServiceIndex
//             (only entries whose `username` is the directory's user, as CORE)
// with the entry's ServiceStateNonce. The NodeName comes from `by-nodename/<NodeName>.info` naming the
// same NodeID (CORE), else from the by-nodeid entry's `nodename` line (ours: the same value in practice).
//
// Ours, not CORE's: a node counts only while it runs. CORE reports every entry it finds, and the
// official node leaves its entries behind when it exits, so CORE's discovery keeps reporting nodes that
// are gone until the URL expires. An entry is live when another process holds the fcntl write lock on
// its sibling `.pid` file (by-nodeid/<id>.pid: the official and our servers hold it while they run; a
// lock on the `.info` itself counts too), or when it names this process and its socket exists (POSIX
// locks of our own process are invisible to F_GETLK).
//
// LocalNodeWatcher keeps the list current: inotify on the entry directories (CORE's events plus
// IN_CLOSE_WRITE, which the kernel sends when a server's entry file is closed, also when the process is
// killed) with a short debounce, and a periodic rescan as a fallback where inotify is unavailable. A
// directory that does not exist yet is watched through its nearest existing ancestor; after adding
// watches the watcher looks again, so a directory created between a look and its watch is not missed.
#pragma once

#include <chrono>
#include <cstddef>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <boost/asio/any_io_executor.hpp>

#include "base/names/node_id.hpp"
#include "server/transport/local/node_directories.hpp"

namespace rr::server::local {

/// One rr+local node found in the entry directories.
struct LocalNodeInfo {
    NodeID node_id;
    std::string node_name;             ///< "" when published by NodeID only
    std::vector<std::string> urls;     ///< one per directory it was found in (see the header comment)
    std::string service_state_nonce;   ///< "" when the entry has none
    int pid = 0;                       ///< from the entry (0 when missing)
    std::string user;                  ///< the entry's `username`
};

struct LocalScanOptions {
    /// Entries read per directory at most (a directory flooded with files costs bounded time).
    std::size_t max_entries_per_dir = 1024;
    /// Public user directories read at most.
    std::size_t max_public_users = 64;
    /// Report nodes of this very process (off for a gateway, which would otherwise find itself and its
    /// demo node; on for tests that publish a node in-process).
    bool include_own_process = false;
};

/// Scans the entry directories of `dirs` once. Unreadable or malformed entries are skipped; never
/// fails. Sorted by NodeID.
std::vector<LocalNodeInfo> find_local_nodes(const NodeDirectories& dirs, const LocalScanOptions& options = {});

struct LocalWatchOptions {
    LocalScanOptions scan;
    /// Rescan period without an inotify event (also how often found nodes are reported again, which
    /// keeps their URLs from expiring in a discovery table). 0 = only on events.
    std::chrono::milliseconds poll_interval{5000};
    /// Delay between an inotify event and the rescan (a starting server writes several files).
    std::chrono::milliseconds debounce{100};
    bool use_inotify = true;
};

/// Watches the entry directories and reports changes. Thread-safe; callbacks run on the watcher's
/// strand, one at a time.
class LocalNodeWatcher : public std::enable_shared_from_this<LocalNodeWatcher> {
public:
    /// `found`: every node of a scan (new or not, so that users can refresh expiry); `lost`: nodes of
    /// the previous scan that are gone (entry removed or its process ended).
    using Listener = std::function<void(const std::vector<LocalNodeInfo>& found, const std::vector<LocalNodeInfo>& lost)>;

    static std::shared_ptr<LocalNodeWatcher> create(boost::asio::any_io_executor executor, NodeDirectories dirs,
                                                    LocalWatchOptions options, Listener listener);
    ~LocalNodeWatcher();

    /// Scans at once, then on changes. `on_started` (may be empty) is called on the watcher's strand
    /// once the first scan has run and its inotify watches are in place (uses_inotify() is final then):
    /// a directory or entry made after that is seen. Not called when stop() came first. Idempotent (a
    /// second call's `on_started` is never called).
    void start(std::function<void()> on_started = {});
    /// Stops watching; no callback runs after stop() returns on another thread than the strand's
    /// (a callback already running finishes). Idempotent.
    void stop();
    /// Rescans now (asynchronously).
    void rescan();
    /// The nodes of the last scan.
    std::vector<LocalNodeInfo> nodes() const;
    /// True when inotify watches the directories (else only polling).
    bool uses_inotify() const;

    class Impl;

private:
    explicit LocalNodeWatcher(std::shared_ptr<Impl> impl) : impl_(std::move(impl)) {}
    std::shared_ptr<Impl> impl_;
};

}  // namespace rr::server::local
