// The TLS byte stream of the server room: OpenSSL (Asio ssl::stream) over a Beast tcp_stream, whose
// timeouts bound the handshakes. The same type carries HTTPS/WSS (server/http), RR over TLS on the
// shared port, and rrs+tcp on both sides, so the StreamPump over it is compiled once
// (tls_stream.cpp); other files see only the extern declaration below.
#pragma once

#include <type_traits>
#include <vector>

#include <boost/asio/ssl/stream.hpp>
#include <boost/beast/core/tcp_stream.hpp>

#include "server/transport/stream_pump.hpp"
#include "server/transport/tls/tls_stream_fwd.hpp"
#include "server/transport/transport.hpp"

namespace rr::server {

static_assert(std::is_same_v<TlsStream, boost::asio::ssl::stream<boost::beast::tcp_stream>>);

/// serve_stream() for a TLS stream (non-template: the pump is compiled in tls_stream.cpp).
bool serve_tls_stream(ConnectionSink& sink, TlsStream stream, const AcceptedStream& info, std::vector<std::byte> initial);
/// start_client_stream() for a TLS stream.
void start_client_tls_stream(TlsStream stream, boost::asio::any_io_executor strand, std::shared_ptr<ConnectionLogic> logic,
                             const ConnectHandler& done);

}  // namespace rr::server

extern template class rr::server::StreamPump<rr::server::TlsStream>;
