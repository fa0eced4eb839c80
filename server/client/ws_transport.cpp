#include "server/client/ws_transport.hpp"

#include <boost/beast/core/tcp_stream.hpp>
#include <boost/beast/websocket.hpp>

#include "server/client/tcp_connector.hpp"
#include "server/http/websocket_byte_stream.hpp"

namespace rr::client {

namespace beast = boost::beast;
namespace websocket = beast::websocket;

namespace {

constexpr const char* kRRSubprotocol = "robotraconteur.robotraconteur.com";

}  // namespace

void ws_transport(ClientStrand strand, const ConnectionUrl& url, const ClientOptions& options,
                  std::shared_ptr<ConnectionLogic> logic, std::function<void(Result<std::shared_ptr<PumpHandle>>)> done) {
    const std::string host = url.host + ":" + std::to_string(url.port);
    const std::string target = url.path.empty() ? std::string("/") : url.path;
    const auto handshake_timeout = options.connect_timeout;
    server::connect_tcp(
        strand, url.host, url.port, options.connect_timeout,
        [strand, host, target, handshake_timeout, logic = std::move(logic), done = std::move(done)](Result<boost::asio::ip::tcp::socket> socket) mutable {
            if (!socket) return done(socket.take_error());
            auto ws = std::make_shared<websocket::stream<beast::tcp_stream>>(beast::tcp_stream(std::move(*socket)));
            ws->set_option(websocket::stream_base::decorator([](websocket::request_type& req) {
                req.set(beast::http::field::sec_websocket_protocol, kRRSubprotocol);
            }));
            ws->next_layer().expires_after(handshake_timeout);  // a peer that never answers the upgrade
            ws->async_handshake(host, target, [ws, strand, logic, done](beast::error_code ec) mutable {
                if (ec) return done(fail(MessageErrorType::ConnectionError, "WebSocket handshake: " + ec.message()));
                ws->next_layer().expires_never();  // from here the RR heartbeat and receive timeout apply
                ws->binary(true);
                using Stream = server::WebSocketByteStream<beast::tcp_stream>;
                auto pump = std::make_shared<server::StreamPump<Stream>>(Stream(std::move(*ws)), strand, logic);
                done(std::shared_ptr<server::PumpHandle>(pump));
                pump->start();
            });
        });
}

}  // namespace rr::client
