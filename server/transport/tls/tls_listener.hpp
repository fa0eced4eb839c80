// TLS on the shared TCP port, service side. TcpListener classifies each accepted socket by its first
// bytes and, when the node has TLS credentials, hands two kinds here:
//   * first byte 0x16 (a TLS ClientHello): TLS handshake with TlsServerCredentials::direct(), then
//     the first four decrypted bytes are classified again: `RRAC` → RR over TLS for the node; anything
//     else → the HttpsHandler (HTTPS, WSS upgrades, and whatever garbage, which gets HTTP's 400);
//   * first bytes `RRAC`: the first message is read (core's StartTlsServer); StreamOp STARTTLS →
//     reply, TLS handshake with TlsServerCredentials::starttls() on the same socket, then RR over
//     TLS (rrs+tcp, wire.md §7); anything else → the plain RR stream with those bytes replayed.
// The handshake and the first decrypted bytes (or the whole first RR message) must arrive within
// the listener's first-bytes timeout; a peer that stalls, or sends anything but TLS after 0x16, is
// closed then. With client_ca set, the handshake fails for a client without a valid certificate.
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <boost/asio/ip/tcp.hpp>

#include "base/names/node_id.hpp"
#include "server/transport/tls/tls_context.hpp"
#include "server/transport/tls/tls_stream_fwd.hpp"
#include "server/transport/transport.hpp"

namespace rr::server {

struct TlsListenOptions {
    std::shared_ptr<TlsServerCredentials> credentials;
    /// The node's identity, for the STARTTLS reply.
    NodeID node_id;
    std::string node_name;
    /// Handshake plus first bytes.
    std::chrono::milliseconds timeout{5000};
    /// Refuse plain connections on the port (as CORE's RequireTls): plain RR is closed after its first
    /// message, plain HTTP gets 403 "TLS required". STARTTLS is of course still accepted.
    bool required = false;
    /// HTTPS/WSS (empty: such connections are closed).
    HttpsHandler https;
    /// Told about every failed TLS accept (peer, reason), e.g. to log or count it. Optional.
    std::function<void(const std::string& peer, const std::string& reason)> on_failure;
};

/// The socket's first byte is 0x16 (nothing consumed yet).
void accept_direct_tls(boost::asio::ip::tcp::socket socket, AcceptedStream info, std::weak_ptr<ConnectionSink> sink,
                       std::shared_ptr<const TlsListenOptions> options);

/// The socket's first four bytes were `RRAC` (`head`, consumed).
void accept_rr_or_starttls(boost::asio::ip::tcp::socket socket, std::vector<std::byte> head, AcceptedStream info,
                           std::weak_ptr<ConnectionSink> sink, std::shared_ptr<const TlsListenOptions> options);

}  // namespace rr::server
