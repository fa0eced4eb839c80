// The WebSocket client transports for rr::client::Client (wire.md §8): TCP connect, for rr+wss a TLS
// handshake (OpenSSL: the server's certificate is verified against ClientOptions::tls_ca_file, or the
// system's trusted certificates, and must name the URL's host), then a WebSocket handshake with the
// subprotocol robotraconteur.robotraconteur.com to the URL's path ("/" unless given, so a service
// behind a reverse proxy at a sub-path is reachable), then the same StreamPump as rr+tcp over
// WebSocketByteStream (binary frames, boundaries carry no meaning). ClientOptions::http_authorization,
// when set, is sent as the handshake's Authorization header (a proxy's login, e.g. nginx basic auth).
// The TLS and WebSocket handshakes together are bounded by ClientOptions::connect_timeout.
#pragma once

#include "server/client/client.hpp"

namespace rr::client {

/// "rr+ws". Errors reach Client::connect as ConnectionError naming the failed step (TCP connect, or
/// the handshake with Beast's message, e.g. "bad status" for a 401 from a proxy).
void ws_transport(ClientStrand strand, const ConnectionUrl& url, const ClientOptions& options,
                  std::shared_ptr<ConnectionLogic> logic, std::function<void(Result<std::shared_ptr<PumpHandle>>)> done);

/// "rr+wss": as ws_transport over TLS. Errors also name the TLS step ("TLS handshake: certificate
/// verify failed", or an unreadable tls_ca_file).
void wss_transport(ClientStrand strand, const ConnectionUrl& url, const ClientOptions& options,
                   std::shared_ptr<ConnectionLogic> logic, std::function<void(Result<std::shared_ptr<PumpHandle>>)> done);

/// "Basic " + base64(user ":" password), for ClientOptions::http_authorization.
std::string basic_authorization(std::string_view user, std::string_view password);

}  // namespace rr::client
