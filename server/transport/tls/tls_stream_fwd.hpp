// TlsStream and HttpsHandler by name only, for headers that pass TLS streams around without using
// them (node.hpp, http_server.hpp, tls_listener.hpp): the Asio SSL and Beast stream headers stay out of
// every file that includes those (tls_stream.hpp has the definitions).
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <vector>

#include <boost/asio/any_io_executor.hpp>
#include <boost/asio/ip/tcp.hpp>

namespace boost::beast {
class unlimited_rate_policy;
template <class Protocol, class Executor, class RatePolicy>
class basic_stream;
}  // namespace boost::beast

namespace boost::asio::ssl {
template <typename Stream>
class stream;
}  // namespace boost::asio::ssl

namespace rr::server {

/// OpenSSL over a Beast tcp_stream (boost::asio::ssl::stream<boost::beast::tcp_stream>).
using TlsStream = boost::asio::ssl::stream<
    boost::beast::basic_stream<boost::asio::ip::tcp, boost::asio::any_io_executor, boost::beast::unlimited_rate_policy>>;

/// Takes a TLS connection (handshake done) whose first decrypted bytes (`initial`) were not `RRAC`:
/// HTTPS requests and WSS upgrades.
/// `hold`: keep alive as long as the connection runs (AcceptedStream::hold).
using HttpsHandler =
    std::function<void(TlsStream stream, std::vector<std::byte> initial, std::shared_ptr<const void> hold)>;

}  // namespace rr::server
