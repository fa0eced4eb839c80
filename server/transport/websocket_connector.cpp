#include "server/transport/websocket_connector.hpp"

#include <openssl/evp.h>
#include <openssl/ssl.h>

#include <boost/asio/ssl.hpp>
#include <boost/beast/core/tcp_stream.hpp>
#include <boost/beast/ssl.hpp>
#include <boost/beast/websocket.hpp>
#include <boost/beast/websocket/ssl.hpp>

#include "core/session/client_session.hpp"
#include "server/transport/tcp_connector.hpp"
#include "server/transport/websocket_byte_stream.hpp"

namespace rr::server {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace websocket = beast::websocket;

namespace {

constexpr const char* kRRSubprotocol = "robotraconteur.robotraconteur.com";

using Clock = std::chrono::steady_clock;

// A step of the connect that failed: the deadline shared by TCP connect and handshakes, or another error.
RRError step_error(std::string_view step, const beast::error_code& ec, const std::string& where,
                   std::chrono::milliseconds limit) {
    if (ec == beast::error::timeout)
        return make_error(MessageErrorType::ConnectionError,
                          "connect to " + where + " timed out after " + seconds_text(limit) + " (" + std::string(step) + ")");
    return make_error(MessageErrorType::ConnectionError, std::string(step) + ": " + ec.message());
}

// The server answered the upgrade with an HTTP status instead of 101: say which, and for a 401 that a
// login is needed (a reverse proxy's basic auth, --http-login in rr).
RRError declined_error(const websocket::response_type& res, bool sent_login) {
    const unsigned status = res.result_int();
    std::string text = "HTTP " + std::to_string(status);
    if (status == 401)
        text += sent_login ? ": the login was refused (wrong user or password?)" : ": a login is needed (the proxy asks for HTTP basic auth)";
    else if (status == 403)
        text += ": forbidden (Origin or address not allowed?)";
    else
        text.append(" ").append(res.reason()).append(": the server declined the WebSocket upgrade");
    return make_error(MessageErrorType::ConnectionError, std::move(text));
}

// The WebSocket handshake on `ws` (its lowest layer connected, TLS done if any), then the pump.
template <class NextLayer>
void websocket_handshake(std::shared_ptr<websocket::stream<NextLayer>> ws, asio::any_io_executor strand, std::string host,
                         std::string target, std::string authorization, std::chrono::milliseconds limit,
                         std::shared_ptr<ConnectionLogic> logic, ConnectHandler done) {
    ws->set_option(websocket::stream_base::decorator([authorization](websocket::request_type& req) {
        req.set(beast::http::field::sec_websocket_protocol, kRRSubprotocol);
        if (!authorization.empty()) req.set(beast::http::field::authorization, authorization);
    }));
    auto res = std::make_shared<websocket::response_type>();
    const bool sent_login = !authorization.empty();
    ws->async_handshake(*res, host, target, [ws, res, strand, logic, done, host, limit, sent_login](beast::error_code ec) mutable {
        if (ec == websocket::error::upgrade_declined) return done(fail(declined_error(*res, sent_login)));
        if (ec) return done(fail(step_error("WebSocket handshake", ec, host, limit)));
        beast::get_lowest_layer(*ws).expires_never();  // from here the RR heartbeat and receive timeout apply
        start_client_stream(WebSocketByteStream<NextLayer>(std::move(*ws)), strand, std::move(logic), done);
    });
}

std::string host_header(const ConnectionUrl& url) { return url.host + ":" + std::to_string(url.port); }
std::string handshake_target(const ConnectionUrl& url) { return url.path.empty() ? std::string("/") : url.path; }

}  // namespace

std::string basic_authorization(std::string_view user, std::string_view password) {
    const std::string plain = std::string(user) + ":" + std::string(password);
    std::string encoded(4 * ((plain.size() + 2) / 3) + 1, '\0');
    const int n = EVP_EncodeBlock(reinterpret_cast<unsigned char*>(encoded.data()),
                                  reinterpret_cast<const unsigned char*>(plain.data()), static_cast<int>(plain.size()));
    encoded.resize(static_cast<std::size_t>(n));
    return "Basic " + encoded;
}

static void connect_ws(asio::any_io_executor strand, const ConnectionUrl& url, const ConnectOptions& options,
                std::shared_ptr<ConnectionLogic> logic, ConnectHandler done) {
    const auto deadline = Clock::now() + options.connect_timeout;  // TCP connect and handshake together
    connect_tcp(strand, url.host, url.port, options.connect_timeout,
                        [strand, host = host_header(url), target = handshake_target(url), options, deadline,
                         logic = std::move(logic), done = std::move(done)](Result<asio::ip::tcp::socket> socket) mutable {
                            if (!socket) return done(socket.take_error());
                            auto ws = std::make_shared<websocket::stream<beast::tcp_stream>>(
                                beast::tcp_stream(std::move(*socket)));
                            ws->next_layer().expires_at(deadline);  // a peer that never answers
                            websocket_handshake(std::move(ws), strand, host, target, options.http_authorization,
                                                options.connect_timeout, std::move(logic), std::move(done));
                        });
}

static void connect_wss(asio::any_io_executor strand, const ConnectionUrl& url, const ConnectOptions& options,
                 std::shared_ptr<ConnectionLogic> logic, ConnectHandler done) {
    // One context per connection: the trust settings come with the options. OpenSSL reference-counts
    // it, so the TLS stream keeps what it needs after this function's copy is gone.
    auto tls = std::make_shared<asio::ssl::context>(asio::ssl::context::tls_client);
    boost::system::error_code ec;
    if (options.tls_ca_file.empty())
        tls->set_default_verify_paths(ec);
    else
        tls->load_verify_file(options.tls_ca_file, ec);
    if (ec)
        return done(fail(MessageErrorType::ConnectionError,
                         "TLS: cannot load the trusted certificates" +
                             (options.tls_ca_file.empty() ? std::string() : " from " + options.tls_ca_file) + ": " +
                             ec.message()));
    // This client's own certificate (mTLS), presented when the server asks for one.
    if (!options.tls_certificate_file.empty() || !options.tls_private_key_file.empty()) {
        const std::string& cert = options.tls_certificate_file;
        const std::string& key = options.tls_private_key_file.empty() ? cert : options.tls_private_key_file;
        tls->use_certificate_chain_file(cert, ec);
        if (ec) return done(fail(MessageErrorType::ConnectionError, "TLS: " + cert + ": no PEM certificate chain (" + ec.message() + ")"));
        tls->use_private_key_file(key, asio::ssl::context::pem, ec);
        if (ec) return done(fail(MessageErrorType::ConnectionError, "TLS: " + key + ": " + ec.message()));
    }
    tls->set_verify_mode(asio::ssl::verify_peer);
    const auto deadline = Clock::now() + options.connect_timeout;  // TCP connect and both handshakes together
    connect_tcp(
        strand, url.host, url.port, options.connect_timeout,
        [strand, tls, url, options, deadline, logic = std::move(logic), done = std::move(done)](Result<asio::ip::tcp::socket> socket) mutable {
            if (!socket) return done(socket.take_error());
            using TlsStream = beast::ssl_stream<beast::tcp_stream>;
            auto ws = std::make_shared<websocket::stream<TlsStream>>(beast::tcp_stream(std::move(*socket)), *tls);
            beast::get_lowest_layer(*ws).expires_at(deadline);
            auto& tls_stream = ws->next_layer();
            if (!SSL_set_tlsext_host_name(tls_stream.native_handle(), url.host.c_str()))  // SNI
                return done(fail(MessageErrorType::ConnectionError, "TLS: bad host name " + url.host));
            tls_stream.set_verify_callback(asio::ssl::host_name_verification(url.host));
            tls_stream.async_handshake(
                asio::ssl::stream_base::client,
                [ws, tls, strand, url, options, logic, done](beast::error_code ec) mutable {
                    if (ec) return done(fail(step_error("TLS handshake", ec, host_header(url), options.connect_timeout)));
                    websocket_handshake(std::move(ws), strand, host_header(url), handshake_target(url),
                                        options.http_authorization, options.connect_timeout, std::move(logic),
                                        std::move(done));
                });
        });
}

void WebSocketConnector::connect(asio::any_io_executor strand, const ConnectionUrl& url, const ConnectOptions& options,
                                 std::shared_ptr<ConnectionLogic> logic, ConnectHandler done) {
    if (tls_)
        connect_wss(std::move(strand), url, options, std::move(logic), std::move(done));
    else
        connect_ws(std::move(strand), url, options, std::move(logic), std::move(done));
}

}  // namespace rr::server
