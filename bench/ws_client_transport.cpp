#include "bench/ws_client_transport.hpp"

#include <boost/beast/core/tcp_stream.hpp>
#include <boost/beast/websocket.hpp>

#include "server/client/client.hpp"
#include "server/client/tcp_connector.hpp"
#include "server/http/websocket_byte_stream.hpp"

namespace rr::bench {

namespace beast = boost::beast;
namespace websocket = beast::websocket;

namespace {

constexpr const char* kRRSubprotocol = "robotraconteur.robotraconteur.com";

void ws_transport(client::ClientStrand strand, const ConnectionUrl& url, const client::ClientOptions& options,
                  std::shared_ptr<server::ConnectionLogic> logic,
                  std::function<void(Result<std::shared_ptr<server::PumpHandle>>)> done) {
    const std::string host = url.host + ":" + std::to_string(url.port);
    server::connect_tcp(
        strand, url.host, url.port, options.connect_timeout,
        [strand, host, logic = std::move(logic), done = std::move(done)](Result<boost::asio::ip::tcp::socket> socket) mutable {
            if (!socket) return done(socket.take_error());
            auto ws = std::make_shared<websocket::stream<beast::tcp_stream>>(beast::tcp_stream(std::move(*socket)));
            ws->set_option(websocket::stream_base::decorator([](websocket::request_type& req) {
                req.set(beast::http::field::sec_websocket_protocol, kRRSubprotocol);
            }));
            ws->async_handshake(host, "/", [ws, strand, logic, done](beast::error_code ec) mutable {
                if (ec) return done(fail(MessageErrorType::ConnectionError, "WebSocket handshake: " + ec.message()));
                ws->binary(true);
                using Stream = server::WebSocketByteStream<beast::tcp_stream>;
                auto pump = std::make_shared<server::StreamPump<Stream>>(Stream(std::move(*ws)), strand, logic);
                done(std::shared_ptr<server::PumpHandle>(pump));
                pump->start();
            });
        });
}

}  // namespace

void register_ws_client_transport() { client::register_client_transport("rr+ws", ws_transport); }

}  // namespace rr::bench
