// rr+tcp, service side: accepts TCP connections and tells raw RR from HTTP by the first four bytes, as
// CORE's TcpTransport does (wire.md §6.1: `RRAC` → an RR stream for the ConnectionSink; anything else
// → the HttpHandler, which serves plain HTTP and WebSocket upgrades; without one: 404 and close).
// With TLS options (tls/tls_listener.hpp) the same port also takes TLS: a first byte 0x16 (a TLS
// ClientHello) → the TLS handshake, then the decrypted stream is classified again (RR over TLS,
// HTTPS, WSS); and a first RR message StreamOp STARTTLS → rrs+tcp. Without TLS options the plain
// paths are exactly as before (no extra read, copy or allocation).
// With an AddressLimiter, a connection beyond the limit of open connections from its IP address is
// refused (HTTP: 429 with the reason; RR: closed) and each accepted one holds its slot until it ends.
// Sockets get TCP_NODELAY. A socket that sends nothing within first_bytes_timeout is dropped.
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <boost/asio/ip/tcp.hpp>

#include "server/transport/transport.hpp"

namespace rr::server {

/// Takes a socket whose first bytes (`initial`) were not `RRAC`: HTTP requests, WebSocket upgrades.
/// `hold` is kept alive as long as the connection runs (AcceptedStream::hold; may be null).
using HttpHandler = std::function<void(boost::asio::ip::tcp::socket socket, std::vector<std::byte> initial,
                                       std::shared_ptr<const void> hold)>;

struct TlsListenOptions;
class AddressLimiter;

/// Runs a plain RR connection whose first bytes (`initial`, starting with `RRAC`) were already read.
bool serve_plain_rr(ConnectionSink& sink, boost::asio::ip::tcp::socket socket, const AcceptedStream& info,
                    std::vector<std::byte> initial);

/// `rr+tcp://<address>:<port>/` for a local TCP endpoint (IPv6 in brackets, without scope): the base
/// of the URLs the service index reports (wire.md §11.2).
std::string tcp_base_url(const boost::asio::ip::tcp::endpoint& local);

struct TcpListenerOptions {
    /// How long an accepted socket may take to send its first 4 bytes (wire.md §6.1: 5 s).
    std::chrono::milliseconds first_bytes_timeout{5000};
    /// Where non-RR sockets go (empty: answer 404 and close).
    HttpHandler http;
    /// TLS on this port (nullptr: none; a first byte 0x16 then goes to `http` like any non-RR socket).
    std::shared_ptr<const TlsListenOptions> tls;
    /// Open connections per client IP address (nullptr: no limit). A connection over the limit is
    /// refused: an HTTP request or WebSocket upgrade gets 429 with the reason, raw RR and TLS are closed.
    std::shared_ptr<AddressLimiter> address_limiter;
    /// Told about each connection refused by `address_limiter` (address, reason), for the log.
    std::function<void(const std::string& address, const std::string& reason)> on_limited;
};

class TcpListener : public Listener, public std::enable_shared_from_this<TcpListener> {
public:
    /// Binds and listens on `address:port` (port 0 = ephemeral). `::` is one dual-stack socket
    /// (IPV6_V6ONLY off: IPv4 clients too); on a host without IPv6 it falls back to `0.0.0.0`
    /// (fallback_note() says so). Errors: InvalidArgument for a bad address, IOError with the system
    /// message (port in use, …).
    static Result<std::shared_ptr<TcpListener>> open(boost::asio::any_io_executor executor, const std::string& address,
                                                     std::uint16_t port, std::weak_ptr<ConnectionSink> sink,
                                                     TcpListenerOptions options);
    /// Starts accepting.
    void start();

    std::string scheme() const override { return "rr+tcp"; }
    /// The bound address's URL; a wildcard address is reported as loopback (the one address every
    /// client on this host can use).
    std::vector<std::string> urls() const override;
    void stop() override;
    std::uint16_t port() const;
    /// The endpoint as bound: `[::]:port` (both families), or `0.0.0.0:port` after the fallback.
    boost::asio::ip::tcp::endpoint local_endpoint() const;
    /// Why `::` was not used (IPv6 unavailable), for the log; empty when the address was used as given.
    const std::string& fallback_note() const noexcept { return fallback_note_; }

private:
    TcpListener(boost::asio::any_io_executor executor, boost::asio::ip::tcp::acceptor acceptor,
                std::weak_ptr<ConnectionSink> sink, TcpListenerOptions options);
    void accept();
    void detect(boost::asio::ip::tcp::socket socket);
    struct Detect;
    void read_head(std::shared_ptr<Detect> d);

    boost::asio::any_io_executor executor_;  ///< the io_context's, for each connection's own strand
    boost::asio::ip::tcp::acceptor acceptor_;  ///< on a strand of its own (accept vs stop())
    std::weak_ptr<ConnectionSink> sink_;
    TcpListenerOptions options_;
    boost::asio::ip::tcp::endpoint bound_;
    std::string fallback_note_;
};

/// Opens an rr+tcp listener for `node` on `address:port` (port 0 = ephemeral), adds it to the node
/// (which stops it at shutdown) and starts it. The node's limits apply: NodeOptions::first_bytes_timeout
/// always, NodeOptions::address_limiter and on_limited unless `options` names its own. Whoever serves
/// HTTP or TLS on the port passes its handlers in `options` (`http`; `tls`, built with the node's
/// NodeID and NodeName for the STARTTLS reply). `NodeT`: server::Node, or anything with io_context(),
/// options(), add_listener() and weak_from_this() as a ConnectionSink. Returns the listener (its
/// local_endpoint() is the address as bound: see TcpListener::open for `::`). Errors: those of
/// TcpListener::open().
template <class NodeT>
Result<std::shared_ptr<TcpListener>> open_tcp_listener(const std::shared_ptr<NodeT>& node, const std::string& address,
                                                       std::uint16_t port, TcpListenerOptions options = {}) {
    if (!node) return fail(MessageErrorType::InvalidArgument, "no node");
    const auto& node_options = node->options();
    options.first_bytes_timeout = node_options.first_bytes_timeout;
    if (!options.address_limiter) {
        options.address_limiter = node_options.address_limiter;
        if (!options.on_limited) options.on_limited = node_options.on_limited;
    }
    std::weak_ptr<ConnectionSink> sink = node;
    auto listener = TcpListener::open(node->io_context().get_executor(), address, port, sink, std::move(options));
    if (!listener) return listener.take_error();
    node->add_listener(*listener);
    (*listener)->start();
    return *listener;
}

/// As open_tcp_listener(), returning the bound port only.
template <class NodeT>
Result<std::uint16_t> listen_tcp(const std::shared_ptr<NodeT>& node, const std::string& address, std::uint16_t port,
                                 TcpListenerOptions options = {}) {
    auto listener = open_tcp_listener(node, address, port, std::move(options));
    if (!listener) return listener.take_error();
    return (*listener)->port();
}

}  // namespace rr::server
