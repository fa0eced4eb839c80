// rr+ws and rr+wss, client side (wire.md §8): TCP connect, for rr+wss a TLS
// handshake (OpenSSL: the server's certificate is verified against ConnectOptions::tls_ca_file, or the
// system's trusted certificates, and must name the URL's host; ConnectOptions::tls_certificate_file
// and tls_private_key_file, when set, are this client's certificate for a server that asks for one),
// then a WebSocket handshake with the subprotocol robotraconteur.robotraconteur.com to the URL's
// path ("/" unless given, so a service
// behind a reverse proxy at a sub-path is reachable), then the same StreamPump as rr+tcp over
// WebSocketByteStream (binary frames, boundaries carry no meaning). ConnectOptions::http_authorization,
// when set, is sent as the handshake's Authorization header (a proxy's login, e.g. nginx basic auth).
// The TCP connect and the TLS and WebSocket handshakes together are bounded by
// ConnectOptions::connect_timeout (ConnectionError "connect to HOST:PORT timed out after S s (step)").
#pragma once

#include <string>
#include <string_view>

#include "server/transport/transport.hpp"

namespace rr::server {

/// "rr+ws", or "rr+wss" with `tls`. Errors reach the client as ConnectionError naming the failed step
/// (TCP connect, the TLS handshake: "certificate verify failed", an unreadable tls_ca_file, or the
/// WebSocket handshake with Beast's message). An upgrade answered with an HTTP status instead of 101
/// says the status: "HTTP 401: a login is needed (…)" (or "…: the login was refused" when
/// http_authorization was sent), "HTTP 403: forbidden (…)", "HTTP N REASON: the server declined …".
class WebSocketConnector : public Connector {
public:
    explicit WebSocketConnector(bool tls) : tls_(tls) {}
    void connect(boost::asio::any_io_executor strand, const ConnectionUrl& url, const ConnectOptions& options,
                 std::shared_ptr<ConnectionLogic> logic, ConnectHandler done) override;

private:
    bool tls_;
};

/// "Basic " + base64(user ":" password), for ConnectOptions::http_authorization.
std::string basic_authorization(std::string_view user, std::string_view password);

}  // namespace rr::server
