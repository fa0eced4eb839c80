// The client side of rr+local (wire.md §9; CORE LocalTransport::AsyncCreateTransportConnection,
// FindAndConnectLocalSocket): finds the socket of the node an rr+local URL names through the lookup
// entries, and connects to it.
//
// URLs: `rr+local:///?nodename=NAME&service=S`, `rr+local:///?nodeid=ID&service=S`, both together
// (then both entries must name the same socket), and `rr+local://user@localhost/?…` for another user's
// public node. No port; host empty or `localhost`; path `/`.
//
// Search (local_layout.hpp search_dirs): the private entry dir, then the user's public dir, then
// root's public dir; in each, `by-nodeid/<id>.info` (when a NodeID is given; its `nodename` must match
// a given NodeName) or `by-nodename/<name>.info`; the first entry whose socket accepts the connection
// wins. Entries whose socket refuses (dead process: nothing holds the entry's lock) are skipped as
// stale. When nothing connects, the error says why, most specific first:
//   InvalidArgument   the URL's form (port, host, path, user, no NodeID/NodeName);
//   ConnectionError   "no local node named "X" (searched …)" — no entry at all;
//                     "local node named "X" is not running: … stale …" — only dead entries;
//                     "… permission denied …" — an entry or socket this user may not open;
//                     "… does not match …" — NodeID and NodeName entries disagree.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <boost/asio/any_io_executor.hpp>
#include <boost/asio/local/stream_protocol.hpp>

#include "base/error/rr_error.hpp"
#include "base/names/connection_url.hpp"
#include "server/transport/local/local_layout.hpp"
#include "server/transport/local/node_directories.hpp"
#include "server/transport/transport.hpp"

namespace rr::server::local {

/// An entry a lookup found and could connect to.
struct FoundNode {
    std::string socket_path;
    std::string info_path;  ///< the entry that named the socket
    InfoMap info;
};

/// Finds the node `url` names and connects a Unix socket to it, on `executor`. Blocking but short
/// (small file reads and a non-blocking connect; a node whose listen queue is full is reported, not
/// waited for). `dirs`: the node directories to search. Errors: see above.
Result<boost::asio::local::stream_protocol::socket> connect_local_socket(const boost::asio::any_io_executor& executor,
                                                                         const ConnectionUrl& url,
                                                                         const NodeDirectories& dirs,
                                                                         FoundNode* found = nullptr);

/// The rr+local Connector (transport.hpp): finds the node with connect_local_socket() in the directories
/// `dirs()` returns at each connect (default: this process's, so environment overrides set before
/// connecting apply) and runs a StreamPump over the Unix socket.
class LocalConnector : public Connector {
public:
    LocalConnector() : dirs_(default_node_directories) {}
    explicit LocalConnector(std::function<NodeDirectories()> dirs) : dirs_(std::move(dirs)) {}
    void connect(boost::asio::any_io_executor strand, const ConnectionUrl& url, const ConnectOptions& options,
                 std::shared_ptr<ConnectionLogic> logic, ConnectHandler done) override;

private:
    std::function<NodeDirectories()> dirs_;
};

}  // namespace rr::server::local
