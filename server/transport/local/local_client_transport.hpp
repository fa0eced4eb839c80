// rr+local for the typed client (server/client/client.hpp): a ClientTransport that finds the node
// through local_connector.hpp and runs a StreamPump over the Unix socket. Registered for the scheme
// "rr+local" in client.cpp's built-in table.
#pragma once

#include <functional>

#include "server/client/client.hpp"
#include "server/transport/local/node_directories.hpp"

namespace rr::server::local {

/// The rr+local client transport, searching the directories `dirs()` returns at each connect.
client::ClientTransport make_local_client_transport(std::function<NodeDirectories()> dirs);

/// The rr+local client transport with this process's node directories (default_node_directories()
/// at each connect, so environment overrides set before connecting apply).
void local_client_transport(client::ClientStrand strand, const ConnectionUrl& url, const client::ClientOptions& options,
                            std::shared_ptr<ConnectionLogic> logic,
                            std::function<void(Result<std::shared_ptr<PumpHandle>>)> done);

}  // namespace rr::server::local
