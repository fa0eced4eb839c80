#include "server/transport/tls/tls_listener.hpp"

#include <boost/asio/read.hpp>
#include <boost/asio/ssl.hpp>
#include <boost/asio/write.hpp>
#include <boost/beast/core/error.hpp>

#include "core/session/starttls.hpp"
#include "server/transport/tls/tls_stream.hpp"
#include "server/transport/tcp_listener.hpp"

namespace rr::server {

namespace asio = boost::asio;
namespace beast = boost::beast;
using tcp = asio::ip::tcp;

namespace {

bool is_rrac(std::span<const std::byte> head) {
    static constexpr char kMagic[] = "RRAC";
    if (head.size() < 4) return false;
    for (int i = 0; i < 4; ++i)
        if (head[i] != static_cast<std::byte>(kMagic[i])) return false;
    return true;
}

std::string reason_of(const boost::system::error_code& ec) {
    if (ec == beast::error::timeout) return "timed out";
    if (ec == asio::error::eof || ec == asio::ssl::error::stream_truncated) return "closed by the peer";
    return ec.message();
}

void report(const TlsListenOptions& o, const AcceptedStream& info, const std::string& reason) {
    if (o.on_failure) o.on_failure(info.peer, reason);
}

// A server handshake on `stream`, then the first four decrypted bytes. Owns everything until the
// stream is handed on.
struct TlsAccept : std::enable_shared_from_this<TlsAccept> {
    TlsAccept(tcp::socket socket, TlsContextPtr context, AcceptedStream info, std::weak_ptr<ConnectionSink> sink,
              std::shared_ptr<const TlsListenOptions> options, std::string what)
        : context(std::move(context)),
          stream(beast::tcp_stream(std::move(socket)), *this->context),
          info(std::move(info)),
          sink(std::move(sink)),
          options(std::move(options)),
          what(std::move(what)) {}

    // The context stays referenced for the handshake (OpenSSL also holds it for the connection).
    TlsContextPtr context;
    TlsStream stream;
    AcceptedStream info;
    std::weak_ptr<ConnectionSink> sink;
    std::shared_ptr<const TlsListenOptions> options;
    std::string what;  // "TLS" or "rrs+tcp", for reports
    std::vector<std::byte> head = std::vector<std::byte>(4);

    void fail(const std::string& reason) {
        report(*options, info, what + ": " + reason);
        boost::system::error_code ignored;
        stream.lowest_layer().close(ignored);
    }

    // rrs+tcp: after the handshake the client speaks the stream protocol; nothing to classify.
    void handshake_then_serve() {
        auto self = shared_from_this();
        beast::get_lowest_layer(stream).expires_after(options->timeout);
        stream.async_handshake(asio::ssl::stream_base::server, [self](boost::system::error_code ec) {
            if (ec) return self->fail("handshake failed: " + reason_of(ec));
            beast::get_lowest_layer(self->stream).expires_never();
            auto sink = self->sink.lock();
            if (!sink) return self->fail("node stopped");
            serve_tls_stream(*sink, std::move(self->stream), self->info, {});
        });
    }

    // Direct TLS: the handshake, then the first decrypted bytes decide, all within the timeout.
    void handshake_then_detect() {
        auto self = shared_from_this();
        beast::get_lowest_layer(stream).expires_after(options->timeout);
        stream.async_handshake(asio::ssl::stream_base::server, [self](boost::system::error_code ec) {
            if (ec) return self->fail("handshake failed: " + reason_of(ec));
            asio::async_read(self->stream, asio::buffer(self->head), [self](boost::system::error_code ec2, std::size_t) {
                if (ec2) return self->fail("no data after the handshake: " + reason_of(ec2));
                beast::get_lowest_layer(self->stream).expires_never();
                if (is_rrac(self->head)) {
                    auto sink = self->sink.lock();
                    if (!sink) return self->fail("node stopped");
                    serve_tls_stream(*sink, std::move(self->stream), self->info, std::move(self->head));
                } else if (self->options->https) {
                    self->options->https(std::move(self->stream), std::move(self->head), self->info.hold);
                } else {
                    self->fail("neither RR nor a served protocol after the handshake");
                }
            });
        });
    }
};

// The first RR message of a connection on a TLS listener: STARTTLS or not.
struct FirstMessageRead : std::enable_shared_from_this<FirstMessageRead> {
    FirstMessageRead(tcp::socket socket, AcceptedStream info, std::weak_ptr<ConnectionSink> sink,
                     std::shared_ptr<const TlsListenOptions> options)
        : stream(std::move(socket)),
          info(std::move(info)),
          sink(std::move(sink)),
          options(std::move(options)),
          starttls(StartTlsServerConfig{this->options->node_id, this->options->node_name, true,
                                        this->options->credentials->requires_client_certificate()}) {}

    beast::tcp_stream stream;
    AcceptedStream info;
    std::weak_ptr<ConnectionSink> sink;
    std::shared_ptr<const TlsListenOptions> options;
    StartTlsServer starttls;
    std::vector<std::byte> buffer;
    std::vector<std::byte> reply;

    void close() {
        boost::system::error_code ignored;
        stream.socket().close(ignored);
    }

    void read_more() {
        if (starttls.kind() != FirstMessage::need_more) return decided();
        buffer.resize(starttls.bytes_wanted());
        auto self = shared_from_this();
        asio::async_read(stream, asio::buffer(buffer), [self](boost::system::error_code ec, std::size_t n) {
            if (ec) {
                // A plain RR client that goes away (or stalls past the timeout) before its first message
                // is complete is not a TLS failure; the plain path would have dropped it the same way.
                self->close();
                return;
            }
            self->starttls.feed(std::span<const std::byte>(self->buffer.data(), n));
            self->read_more();
        });
    }

    void decided() {
        switch (starttls.kind()) {
            case FirstMessage::need_more: return;
            case FirstMessage::plain: {
                stream.expires_never();
                if (options->required) {
                    report(*options, info, "plain RR refused: TLS is required on this port");
                    return close();
                }
                std::vector<std::byte> initial(starttls.received().begin(), starttls.received().end());
                auto node = sink.lock();
                if (!node) return close();
                serve_plain_rr(*node, stream.release_socket(), info, std::move(initial));
                return;
            }
            case FirstMessage::refused:
            case FirstMessage::start_tls: break;
        }
        reply.assign(starttls.reply().begin(), starttls.reply().end());
        auto self = shared_from_this();
        asio::async_write(stream, asio::buffer(reply), [self](boost::system::error_code ec, std::size_t) {
            if (ec || self->starttls.kind() == FirstMessage::refused) {
                if (!ec) report(*self->options, self->info, "rrs+tcp: STARTTLS refused: " + self->starttls.refusal().message);
                self->close();
                return;
            }
            auto ctx = self->options->credentials->starttls();
            auto tls = std::make_shared<TlsAccept>(self->stream.release_socket(), std::move(ctx), self->info, self->sink,
                                                   self->options, "rrs+tcp");
            tls->handshake_then_serve();
        });
    }
};

}  // namespace

void accept_direct_tls(tcp::socket socket, AcceptedStream info, std::weak_ptr<ConnectionSink> sink,
                       std::shared_ptr<const TlsListenOptions> options) {
    auto ctx = options->credentials->direct();
    auto op = std::make_shared<TlsAccept>(std::move(socket), std::move(ctx), std::move(info), std::move(sink),
                                          std::move(options), "TLS");
    op->handshake_then_detect();
}

void accept_rr_or_starttls(tcp::socket socket, std::vector<std::byte> head, AcceptedStream info,
                           std::weak_ptr<ConnectionSink> sink, std::shared_ptr<const TlsListenOptions> options) {
    const auto timeout = options->timeout;
    auto op = std::make_shared<FirstMessageRead>(std::move(socket), std::move(info), std::move(sink), std::move(options));
    op->stream.expires_after(timeout);  // the rest of the first message within the first-bytes timeout
    op->starttls.feed(head);
    op->read_more();
}

}  // namespace rr::server
