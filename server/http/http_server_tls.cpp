// HTTPS and WSS: the sessions of http_session.hpp over TlsStream. Kept apart from http_server.cpp so
// that the Beast-over-OpenSSL instantiations cost one translation unit (docs/development.md).
#include <boost/beast/websocket/ssl.hpp>

#include "server/http/http_session.hpp"
#include "server/transport/tls/tls_stream.hpp"

namespace rr::server::http {

void HttpServer::handle_tls(TlsStream stream, std::vector<std::byte> initial, std::shared_ptr<const void> hold) {
    auto session = std::make_shared<detail::HttpSession<TlsStream>>(shared_from_this(), std::move(stream));
    session->start(std::move(initial), std::move(hold));
}

HttpsHandler https_handler(std::weak_ptr<HttpServer> server) {
    return [server = std::move(server)](TlsStream stream, std::vector<std::byte> initial, std::shared_ptr<const void> hold) {
        if (auto s = server.lock()) return s->handle_tls(std::move(stream), std::move(initial), std::move(hold));
        boost::system::error_code ignored;
        stream.lowest_layer().close(ignored);
    };
}

}  // namespace rr::server::http
