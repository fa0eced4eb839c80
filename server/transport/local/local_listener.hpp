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
// Accepted connections go to the ConnectionSink (the node; server/transport/transport.hpp) with the
// base URL "rr+local:///", so its service index reports `rr+local:///?nodeid=<id>&service=<name>` as
// CORE does. Like the TCP listener, a connection must send its first 4 bytes (`RRAC`) within
// first_bytes_timeout and is refused while the sink is at its connection limit.
//
// Lifetime: listen_local() adds the listener to its node, which stops it (close()) at shutdown; the
// listener holds the sink weakly. Thread-safety: every member may be called from any thread.
#pragma once

#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include <boost/asio/any_io_executor.hpp>

#include "base/error/rr_error.hpp"
#include "base/names/node_id.hpp"
#include "server/transport/local/node_directories.hpp"
#include "server/transport/local/node_identity.hpp"
#include "server/transport/transport.hpp"

namespace rr::server::local {

struct LocalListenOptions {
    /// Where to publish; default: this process's directories (node_directories.hpp).
    std::optional<NodeDirectories> dirs;
    /// Publish in `<system run>/transport/local/<user>/` (clients of other users in the group that
    /// owns that directory may connect) instead of the private `<user run>/transport/local/`. The
    /// directory must have been created by an administrator: else SystemResourceError.
    bool public_server = false;
    /// How long an accepted socket may take to send its first 4 bytes (as TCP, wire.md §6.1).
    std::chrono::milliseconds first_bytes_timeout{5000};
    /// The ServiceStateNonce the entries start with: the node's (Node::service_state_nonce(); set by
    /// listen_local). Empty: a random one.
    std::string service_state_nonce;
};

class LocalListener : public Listener, public std::enable_shared_from_this<LocalListener> {
public:
    /// Starts listening on `executor` for the node `node_id` / `node_name` (empty: published by NodeID
    /// only), handing connections to `sink`. `reservation`: the node's NodeName as reserved by
    /// reserve_node_name() (how the node got its NodeID); when absent and the node has a NodeName it
    /// is reserved here and must give the node's NodeID. Errors: those of reserve_node_name();
    /// InvalidArgument when the NodeID cache gives the name another NodeID than the node's;
    /// InvalidOperation when the NodeID or NodeName is in use (this process or another);
    /// SystemResourceError / SystemResourcePermissionDenied / IOError for the directories, the
    /// socket (incl. a socket path over 107 bytes) and the entry files.
    static Result<std::shared_ptr<LocalListener>> start(boost::asio::any_io_executor executor,
                                                         std::weak_ptr<ConnectionSink> sink, const NodeID& node_id,
                                                         const std::string& node_name, LocalListenOptions options = {},
                                                         std::optional<NodeNameReservation> reservation = std::nullopt);

    ~LocalListener() override;
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

    /// Writes `service_state_nonce` (the node's new one; empty: a fresh random one) into the `.info`
    /// files (CORE LocalNodeServicesChanged writes the node's GetServiceStateNonce(); local discovery
    /// re-reads a node's service index when the nonce changes). The node calls it when services are
    /// registered or removed (Listener::services_changed).
    void refresh_service_state(const std::string& service_state_nonce = {});
    /// The ServiceStateNonce the entries carry now.
    std::string service_state_nonce() const;
    /// Stops accepting, removes the socket file and the entries, releases the NodeName/NodeID.
    /// Connections already accepted stay with the node. Idempotent.
    void close();

    // Listener
    std::string scheme() const override { return "rr+local"; }
    std::vector<std::string> urls() const override { return {url()}; }
    void stop() override { close(); }
    void services_changed(const std::string& nonce) override { refresh_service_state(nonce); }

    class Impl;

private:
    explicit LocalListener(std::shared_ptr<Impl> impl);
    std::shared_ptr<Impl> impl_;
    std::string socket_path_;
    std::string entry_dir_;
};

/// Opens an rr+local listener for `node` and adds it to the node (which stops it at shutdown and tells
/// it when services change). `NodeT`: server::Node, or anything with io_context(), node_id(),
/// node_name(), options().first_bytes_timeout, add_listener() and weak_from_this() as a ConnectionSink.
/// Errors: those of LocalListener::start().
template <class NodeT>
Result<std::shared_ptr<LocalListener>> listen_local(const std::shared_ptr<NodeT>& node, LocalListenOptions options = {},
                                                    std::optional<NodeNameReservation> reservation = std::nullopt) {
    if (!node) return fail(MessageErrorType::InvalidArgument, "no node");
    options.first_bytes_timeout = node->options().first_bytes_timeout;
    if constexpr (requires(NodeT& n) { n.service_state_nonce(); })
        if (options.service_state_nonce.empty()) options.service_state_nonce = node->service_state_nonce();
    std::weak_ptr<ConnectionSink> sink = node;
    auto l = LocalListener::start(node->io_context().get_executor(), sink, node->node_id(), node->node_name(),
                                  std::move(options), std::move(reservation));
    if (l) node->add_listener(*l);
    return l;
}

}  // namespace rr::server::local
