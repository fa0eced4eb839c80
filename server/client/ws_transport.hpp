// The rr+ws client transport for rr::client::Client (wire.md §8): TCP connect, a WebSocket handshake
// on "/" with the subprotocol robotraconteur.robotraconteur.com, then the same StreamPump as rr+tcp
// over WebSocketByteStream (binary frames, boundaries carry no meaning). The handshake asks for the
// URL's path ("/" unless given), so a service behind a reverse proxy at a sub-path is reachable.
// No TLS (rr+wss).
#pragma once

#include "server/client/client.hpp"

namespace rr::client {

/// The transport Client uses for "rr+ws" URLs (built in; see register_client_transport). Errors reach
/// Client::connect as ConnectionError naming the failed step (TCP connect, or the handshake with
/// Beast's message).
void ws_transport(ClientStrand strand, const ConnectionUrl& url, const ClientOptions& options,
                  std::shared_ptr<ConnectionLogic> logic, std::function<void(Result<std::shared_ptr<PumpHandle>>)> done);

}  // namespace rr::client
