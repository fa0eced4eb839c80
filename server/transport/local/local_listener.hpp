// The service side of rr+local (wire.md §9; CORE LocalTransport::StartServerAsNodeName / AsNodeID):
// a node listens on a Unix socket and publishes lookup entries so that clients on this computer find
// it by NodeName or NodeID.
//
// What start() does, in CORE's order:
//   1. a node with a NodeName holds that name (node_identity.hpp; the node's NodeID must be the one the
//      NodeID cache gives the name); a node without one is published by NodeID only;
//   2. the NodeID is held inside this process (two nodes of one process with one NodeID are refused);
//   3. the socket `<user run>/socket/<16 random [A-Za-z0-9]>.sock` (public: `<system run>/transport/
//      local/<user>/socket/…`) is bound, listened on and set to mode 0770;
//   4. `by-nodeid/<nodeid>.pid` + `.info` and, when named, `by-nodename/<name>.pid` + `.info` are
//      created (mode 0640) in the entry directory and held with an fcntl write lock; the `.info` lists
//      ServiceStateNonce, nodeid `{…}`, nodename, pid, socket, username (local_layout.hpp format).
//      A lock held by another process means that NodeID/NodeName is running: InvalidOperation.
// close() (and the destructor) stops accepting, removes the socket file and the entries (CORE leaves
// its `.info`/`.pid` behind, unlocked; we remove ours while still holding their locks), and releases
// the name. A process that dies leaves unlocked entries and a dead socket: clients report them stale.
//
// Accepted connections are served by the node (Node::serve_stream_as) with the base URL
// "rr+local:///", so its service index reports `rr+local:///?nodeid=<id>&service=<name>` as CORE does.
// Like the TCP listener, a connection must send its first 4 bytes (`RRAC`) within the node's
// first_bytes_timeout and counts against NodeOptions::max_connections.
//
// Lifetime: the listener keeps the node alive; close it before (or when) the node shuts down: after
// Node::shutdown() nobody accepts any more, and clients that still find the socket would wait.
// Thread-safety: every member may be called from any thread.
#pragma once

#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "core/error/rr_error.hpp"
#include "server/transport/local/node_directories.hpp"
#include "server/transport/local/node_identity.hpp"

namespace rr::server {
class Node;
}

namespace rr::server::local {

struct LocalListenOptions {
    /// Where to publish; default: this process's directories (node_directories.hpp).
    std::optional<NodeDirectories> dirs;
    /// Publish in `<system run>/transport/local/<user>/` (clients of other users in the group that
    /// owns that directory may connect) instead of the private `<user run>/transport/local/`. The
    /// directory must have been created by an administrator: else SystemResourceError.
    bool public_server = false;
};

class LocalListener : public std::enable_shared_from_this<LocalListener> {
public:
    /// Starts listening for `node`. `reservation`: the node's NodeName as reserved by
    /// reserve_node_name() (how the node got its NodeID); when absent and the node has a NodeName it
    /// is reserved here and must give the node's NodeID. Errors: those of reserve_node_name();
    /// InvalidArgument when the NodeID cache gives the name another NodeID than the node's;
    /// InvalidOperation when the NodeID or NodeName is in use (this process or another);
    /// SystemResourceError / SystemResourcePermissionDenied / IOError for the directories, the
    /// socket (incl. a socket path over 107 bytes) and the entry files.
    static Result<std::shared_ptr<LocalListener>> start(std::shared_ptr<Node> node, LocalListenOptions options = {},
                                                         std::optional<NodeNameReservation> reservation = std::nullopt);

    ~LocalListener();
    LocalListener(const LocalListener&) = delete;
    LocalListener& operator=(const LocalListener&) = delete;

    /// The listening socket's path.
    const std::string& socket_path() const noexcept { return socket_path_; }
    /// The entry directory (holding by-nodeid/ and by-nodename/).
    const std::string& entry_dir() const noexcept { return entry_dir_; }
    /// `rr+local:///?nodeid=<id>` (CORE GetServerListenUrls).
    std::string url() const;
    /// The `.info` files this listener holds (by-nodeid first).
    std::vector<std::string> info_files() const;

    /// Picks a new ServiceStateNonce and rewrites the `.info` files (CORE LocalNodeServicesChanged;
    /// local discovery re-reads a node's service index when the nonce changes). Call when services
    /// are registered or removed.
    void refresh_service_state();
    /// Stops accepting, removes the socket file and the entries, releases the NodeName/NodeID.
    /// Connections already accepted stay with the node. Idempotent.
    void close();

    class Impl;

private:
    LocalListener(std::shared_ptr<Impl> impl, std::shared_ptr<Node> node);
    std::shared_ptr<Impl> impl_;
    std::shared_ptr<Node> node_;
    std::string socket_path_;
    std::string entry_dir_;
};

/// Shorthand for LocalListener::start().
inline Result<std::shared_ptr<LocalListener>> listen_local(std::shared_ptr<Node> node, LocalListenOptions options = {},
                                                           std::optional<NodeNameReservation> reservation = std::nullopt) {
    return LocalListener::start(std::move(node), std::move(options), std::move(reservation));
}

}  // namespace rr::server::local
