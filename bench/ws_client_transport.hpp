// The rr+ws client transport for rr::client::Client (wire.md §8): TCP connect, a WebSocket handshake
// on "/" with the subprotocol robotraconteur.robotraconteur.com, then the same StreamPump as rr+tcp
// over WebSocketByteStream (binary frames, boundaries carry no meaning). No TLS (rr+wss).
#pragma once

namespace rr::bench {

/// Registers the transport for the "rr+ws" scheme (idempotent). Errors reach Client::connect as
/// ConnectionError naming the failed step (TCP connect, or the handshake with Beast's message).
void register_ws_client_transport();

}  // namespace rr::bench
