#include "server/transport/tls/rrs_connector.hpp"

#include <arpa/inet.h>

#include <openssl/ssl.h>

#include <boost/asio/read.hpp>
#include <boost/asio/ssl.hpp>
#include <boost/asio/write.hpp>
#include <boost/beast/core/error.hpp>

#include "core/session/starttls.hpp"
#include "server/transport/tcp_connector.hpp"
#include "server/transport/tls/tls_context.hpp"
#include "server/transport/tls/tls_stream.hpp"

namespace rr::server {

namespace asio = boost::asio;
namespace beast = boost::beast;
using tcp = asio::ip::tcp;

namespace {

std::string reason_of(const boost::system::error_code& ec) {
    if (ec == beast::error::timeout) return "timed out";
    if (ec == asio::error::eof) return "connection closed by the server";
    return ec.message();
}

bool is_ip_literal(const std::string& host) {
    unsigned char buf[16];
    return inet_pton(AF_INET, host.c_str(), buf) == 1 || inet_pton(AF_INET6, host.c_str(), buf) == 1;
}

struct RrsConnect : std::enable_shared_from_this<RrsConnect> {
    RrsConnect(tcp::socket socket, TlsContextPtr context, ConnectionUrl url, StartTlsClientConfig config,
               asio::any_io_executor strand, std::shared_ptr<ConnectionLogic> logic, ConnectHandler done)
        : stream(std::move(socket)),
          context(std::move(context)),
          url(std::move(url)),
          starttls(std::move(config), mono_now()),
          strand(std::move(strand)),
          logic(std::move(logic)),
          done(std::move(done)) {}

    beast::tcp_stream stream;
    TlsContextPtr context;
    ConnectionUrl url;
    StartTlsClient starttls;
    asio::any_io_executor strand;
    std::shared_ptr<ConnectionLogic> logic;
    ConnectHandler done;
    std::vector<std::byte> buffer;
    std::optional<TlsStream> tls;

    void fail(RRError e) {
        boost::system::error_code ignored;
        if (tls) tls->lowest_layer().close(ignored);  // the TCP stream was moved into it
        else stream.socket().close(ignored);
        done(fail_result(std::move(e)));
    }
    static Result<std::shared_ptr<PumpHandle>> fail_result(RRError e) { return rr::fail(std::move(e)); }

    void send_request() {
        if (starttls.state() == StartTlsState::failed) return fail(starttls.error());
        auto self = shared_from_this();
        asio::async_write(stream, asio::buffer(starttls.request().data(), starttls.request().size()),
                          [self](boost::system::error_code ec, std::size_t) {
                              if (ec)
                                  return self->fail(make_error(MessageErrorType::ConnectionError,
                                                               "rrs+tcp: cannot send STARTTLS: " + reason_of(ec)));
                              self->read_reply();
                          });
    }

    void read_reply() {
        buffer.resize(starttls.bytes_wanted());
        auto self = shared_from_this();
        asio::async_read(stream, asio::buffer(buffer), [self](boost::system::error_code ec, std::size_t n) {
            if (ec)
                return self->fail(make_error(MessageErrorType::ConnectionError,
                                             "rrs+tcp: no STARTTLS answer: " + reason_of(ec) +
                                                 (ec == asio::error::eof ? " (is this an RR node with TLS?)" : "")));
            self->starttls.feed(std::span<const std::byte>(self->buffer.data(), n), mono_now());
            switch (self->starttls.state()) {
                case StartTlsState::waiting: return self->read_reply();
                case StartTlsState::failed: {
                    RRError e = self->starttls.error();
                    e.message = "rrs+tcp: STARTTLS refused: " + e.message;
                    return self->fail(std::move(e));
                }
                case StartTlsState::done: return self->handshake();
            }
        });
    }

    void handshake() {
        tls.emplace(std::move(stream), *context);
        if (!is_ip_literal(url.host)) SSL_set_tlsext_host_name(tls->native_handle(), url.host.c_str());  // SNI
        auto self = shared_from_this();
        tls->async_handshake(asio::ssl::stream_base::client, [self](boost::system::error_code ec) {
            if (ec)
                return self->fail(make_error(MessageErrorType::ConnectionError, "rrs+tcp: TLS handshake: " + reason_of(ec)));
            if (auto named = verify_rrs_server_name(self->tls->native_handle(), self->url.host,
                                                    self->starttls.result().remote_node_id);
                !named)
                return self->fail(named.error());
            beast::get_lowest_layer(*self->tls).expires_never();  // the RR heartbeat and receive timeout apply now
            start_client_tls_stream(std::move(*self->tls), self->strand, std::move(self->logic), self->done);
        });
    }
};

}  // namespace

void RrsTcpConnector::connect(asio::any_io_executor strand, const ConnectionUrl& url, const ConnectOptions& options,
                              std::shared_ptr<ConnectionLogic> logic, ConnectHandler done) {
    auto context = make_tls_client_context(
        TlsClientFiles{options.tls_ca_file, options.tls_certificate_file, options.tls_private_key_file});
    if (!context) return done(context.take_error());
    StartTlsClientConfig config;
    config.target_node_id = url.node_id;
    config.target_node_name = url.node_name;
    config.mutual_auth = !options.tls_certificate_file.empty();
    config.timeout = options.connect_timeout;
    const auto timeout = options.connect_timeout;
    connect_tcp(strand, url.host, url.port, timeout,
                [strand, url, config, timeout, context = std::move(*context), logic = std::move(logic),
                 done = std::move(done)](Result<tcp::socket> socket) mutable {
                    if (!socket) return done(socket.take_error());
                    auto op = std::make_shared<RrsConnect>(std::move(*socket), std::move(context), std::move(url),
                                                           std::move(config), std::move(strand), std::move(logic),
                                                           std::move(done));
                    op->stream.expires_after(timeout);  // STARTTLS and the handshake together
                    op->send_request();
                });
}

}  // namespace rr::server
