// rrs+tcp, client side (wire.md §7): TCP connect, the plain STARTTLS exchange (core's StartTlsClient),
// then a TLS handshake as client on the same socket, then the same StreamPump as rr+tcp over the TLS
// stream (the logic's CreateConnection is the first message inside TLS).
//
// Trust: ConnectOptions::tls_ca_file, or the system's store. The server's certificate must chain to it
// and name either the URL's host (DNS or IP subject alternative name, as for HTTPS) or the remote node
// as the official library does (subject CN "Robot Raconteur Node {NodeID}", where NodeID is the URL's
// `nodeid` or else the one the STARTTLS reply came from). RR's critical marker extensions are
// accepted, so a certificate issued for the official library verifies when its root is the CA.
// With ConnectOptions::tls_certificate_file the client presents its own certificate (mTLS) and says
// `mutualauth` in STARTTLS. STARTTLS and the handshake together are bounded by connect_timeout.
#pragma once

#include "server/transport/transport.hpp"

namespace rr::server {

/// Errors reach the client as the server's STARTTLS error (ConnectionError "Server certificate not
/// loaded" from a node without TLS, NodeNotFound), ConnectionError "rrs+tcp: TLS handshake: …"
/// (e.g. "certificate verify failed"), AuthenticationError when the certificate names neither the
/// host nor the node, or ConnectionError for TCP and unreadable certificate files.
class RrsTcpConnector : public Connector {
public:
    void connect(boost::asio::any_io_executor strand, const ConnectionUrl& url, const ConnectOptions& options,
                 std::shared_ptr<ConnectionLogic> logic, ConnectHandler done) override;
};

}  // namespace rr::server
