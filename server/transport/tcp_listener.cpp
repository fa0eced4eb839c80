#include "server/transport/tcp_listener.hpp"

#include "server/transport/tls/tls_listener.hpp"
#include "server/common/address_limiter.hpp"
#include "server/common/connection_strand.hpp"

#include <array>
#include <string_view>

#include <boost/asio/ip/v6_only.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/read.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>
#include <boost/asio/write.hpp>

namespace rr::server {

namespace asio = boost::asio;
using tcp = asio::ip::tcp;

std::string tcp_base_url(const tcp::endpoint& local) {
    std::string host = local.address().to_string();
    if (local.address().is_v6()) host = "[" + host.substr(0, host.find('%')) + "]";
    return "rr+tcp://" + host + ":" + std::to_string(local.port()) + "/";
}

namespace {

// Opens, binds and listens on `ep`. An IPv6 wildcard gets IPV6_V6ONLY off: one socket for both
// families (IPv4 clients arrive as ::ffff:a.b.c.d), as the official node's TCP server takes both.
boost::system::error_code open_acceptor(tcp::acceptor& acceptor, const tcp::endpoint& ep) {
    boost::system::error_code ec;
    acceptor.open(ep.protocol(), ec);
    if (!ec && ep.address().is_v6() && ep.address().is_unspecified()) acceptor.set_option(asio::ip::v6_only(false), ec);
    if (!ec) acceptor.set_option(tcp::acceptor::reuse_address(true), ec);
    if (!ec) acceptor.bind(ep, ec);
    if (!ec) acceptor.listen(asio::socket_base::max_listen_connections, ec);
    if (ec) {
        boost::system::error_code ignored;
        acceptor.close(ignored);
    }
    return ec;
}

// Errors that say the host has no IPv6 (a kernel booted with ipv6.disable=1, a sandbox that refuses
// AF_INET6 sockets), as opposed to a port in use or a missing permission.
bool ipv6_unavailable(const boost::system::error_code& ec) {
    return ec == asio::error::address_family_not_supported || ec == boost::system::errc::address_not_available ||
           ec == boost::system::errc::protocol_not_supported;
}

}  // namespace

Result<std::shared_ptr<TcpListener>> TcpListener::open(asio::any_io_executor executor, const std::string& address,
                                                       std::uint16_t port, std::weak_ptr<ConnectionSink> sink,
                                                       TcpListenerOptions options) {
    boost::system::error_code ec;
    auto addr = asio::ip::make_address(address, ec);
    if (ec) return fail(MessageErrorType::InvalidArgument, "bad listen address \"" + address + "\": " + ec.message());
    // The acceptor's own strand: stop() closes it while an accept completion may be starting the
    // next accept on another worker thread (a data race ThreadSanitizer reported).
    tcp::acceptor acceptor(asio::make_strand(executor));
    ec = open_acceptor(acceptor, tcp::endpoint(addr, port));
    std::string note;
    if (ec && addr.is_v6() && addr.is_unspecified() && ipv6_unavailable(ec)) {
        // `::` on a host without IPv6: the IPv4 wildcard serves what can be served.
        note = "IPv6 is not available (" + ec.message() + "): listening on 0.0.0.0 (IPv4 only)";
        ec = open_acceptor(acceptor, tcp::endpoint(asio::ip::address_v4::any(), port));
    }
    if (ec)
        return fail(MessageErrorType::IOError, "cannot listen on " + address + ":" + std::to_string(port) + ": " + ec.message());
    std::shared_ptr<TcpListener> listener(new TcpListener(executor, std::move(acceptor), std::move(sink), std::move(options)));
    listener->fallback_note_ = std::move(note);
    return listener;
}

TcpListener::TcpListener(asio::any_io_executor executor, tcp::acceptor acceptor, std::weak_ptr<ConnectionSink> sink,
                         TcpListenerOptions options)
    : executor_(std::move(executor)), acceptor_(std::move(acceptor)), sink_(std::move(sink)), options_(std::move(options)) {
    boost::system::error_code ec;
    bound_ = acceptor_.local_endpoint(ec);
}

void TcpListener::start() {
    auto self = shared_from_this();
    asio::post(acceptor_.get_executor(), [self] { self->accept(); });
}

void TcpListener::stop() {
    auto self = shared_from_this();
    asio::post(acceptor_.get_executor(), [self] {
        boost::system::error_code ignored;
        self->acceptor_.close(ignored);
    });
}

std::uint16_t TcpListener::port() const { return bound_.port(); }
tcp::endpoint TcpListener::local_endpoint() const { return bound_; }

std::vector<std::string> TcpListener::urls() const {
    auto ep = bound_;
    if (ep.address().is_unspecified())
        ep.address(ep.address().is_v6() ? asio::ip::address(asio::ip::address_v6::loopback())
                                        : asio::ip::address(asio::ip::address_v4::loopback()));
    return {tcp_base_url(ep)};
}

void TcpListener::accept() {
    auto self = shared_from_this();
    acceptor_.async_accept(connection_strand(executor_), [self](boost::system::error_code ec, tcp::socket socket) {
        if (ec == asio::error::operation_aborted || !self->acceptor_.is_open()) return;
        if (!ec) self->detect(std::move(socket));
        self->accept();
    });
}

namespace {

// Whether four bytes can begin an HTTP/1.1 request: the start of "METHOD " for a standard method
// (RFC 9110 §9; "GET\t" as CORE accepts), or CR/LF (the empty lines a server may skip first). Anything
// else is neither RR nor HTTP (a wrong magic, binary garbage): dropped at once rather than handed to
// the HTTP parser, which waits for the end of a header that never comes (until the read timeout).
// Extension methods are not served by the gateway, so nothing is lost by refusing them here.
bool could_begin_http(const std::array<std::byte, 4>& head) {
    const std::string_view h(reinterpret_cast<const char*>(head.data()), head.size());
    if (h[0] == '\r' || h[0] == '\n') return true;
    static constexpr std::string_view kStarts[] = {"GET ", "GET\t", "HEAD", "POST", "PUT ", "DELE", "OPTI",
                                                   "PATC", "CONN", "TRAC"};
    for (auto s : kStarts)
        if (h == s) return true;
    return false;
}

AcceptedStream accepted_info(const tcp::socket& socket) {
    AcceptedStream info;
    boost::system::error_code ec;
    auto local = socket.local_endpoint(ec);
    if (!ec) info.local_url = tcp_base_url(local);
    auto remote = socket.remote_endpoint(ec);
    if (!ec) info.peer = remote.address().to_string() + ":" + std::to_string(remote.port());
    return info;
}

bool is_rrac(const std::array<std::byte, 4>& h) {
    static constexpr char kMagic[] = "RRAC";
    for (int i = 0; i < 4; ++i)
        if (h[i] != static_cast<std::byte>(kMagic[i])) return false;
    return true;
}

}  // namespace

bool serve_plain_rr(ConnectionSink& sink, tcp::socket socket, const AcceptedStream& info, std::vector<std::byte> initial) {
    return serve_stream(sink, std::move(socket), info, std::move(initial));
}

struct TcpListener::Detect {
    tcp::socket socket;
    asio::steady_timer timer;
    std::array<std::byte, 4> head{};
    std::shared_ptr<const void> hold;  // the per-address slot (null without a limiter)
    std::string refused;               // non-empty: over the per-address limit, this is why
};

namespace {

// The client's IP address as the limiter counts it: an IPv4-mapped IPv6 address counts as IPv4.
std::string client_address(const tcp::socket& socket) {
    boost::system::error_code ec;
    auto remote = socket.remote_endpoint(ec);
    if (ec) return {};
    auto a = remote.address();
    if (a.is_v6() && a.to_v6().is_v4_mapped()) a = asio::ip::make_address_v4(asio::ip::v4_mapped, a.to_v6());
    return a.to_string();
}

// 429 for an HTTP request or WebSocket upgrade over the per-address limit (RFC 6585 §4), then close.
// What the client sent after its first four bytes is read and dropped (for at most 2 s) before the
// close, so that the close is a FIN, not a reset that could discard the answer at the client.
void refuse_http(tcp::socket socket, const std::string& reason) {
    struct Out {
        tcp::socket socket;
        asio::steady_timer timer;
        std::string text;
        std::array<char, 512> sink{};
        void drain(std::shared_ptr<Out> self) {
            socket.async_read_some(asio::buffer(sink), [self](boost::system::error_code ec, std::size_t) {
                if (!ec) return self->drain(self);
                self->timer.cancel();
                boost::system::error_code ignored;
                self->socket.close(ignored);
            });
        }
    };
    const std::string body = reason + "\n";
    auto executor = socket.get_executor();
    auto out = std::make_shared<Out>(Out{std::move(socket), asio::steady_timer(executor), {}, {}});
    out->text = "HTTP/1.1 429 Too Many Requests\r\nConnection: close\r\nRetry-After: 5\r\n"
                "Content-Type: text/plain; charset=utf-8\r\nContent-Length: " +
                std::to_string(body.size()) + "\r\n\r\n" + body;
    asio::async_write(out->socket, asio::buffer(out->text), [out](boost::system::error_code ec, std::size_t) {
        boost::system::error_code ignored;
        if (ec) return out->socket.close(ignored);
        out->socket.shutdown(tcp::socket::shutdown_send, ignored);
        out->timer.expires_after(std::chrono::seconds(2));
        out->timer.async_wait([out](boost::system::error_code tec) {
            boost::system::error_code ignored2;
            if (!tec) out->socket.close(ignored2);
        });
        out->drain(out);
    });
}

}  // namespace

void TcpListener::detect(tcp::socket socket) {
    auto sink = sink_.lock();
    if (!sink || !sink->can_accept()) {
        boost::system::error_code ignored;
        socket.close(ignored);  // over the connection limit: refuse without reading
        return;
    }
    boost::system::error_code ignored;
    socket.set_option(tcp::no_delay(true), ignored);

    auto d = std::make_shared<Detect>(Detect{std::move(socket), asio::steady_timer(socket.get_executor()), {}, {}, {}});
    if (auto& limiter = options_.address_limiter) {
        const auto address = client_address(d->socket);
        if (auto slot = limiter->acquire(address)) {
            d->hold = std::move(slot);
        } else {
            d->refused = "too many connections from " + address + " (at most " +
                         std::to_string(limiter->max_per_address()) + " per address)";
            if (options_.on_limited) options_.on_limited(address, d->refused);
        }
    }
    d->timer.expires_after(options_.first_bytes_timeout);
    d->timer.async_wait([d](boost::system::error_code ec) {
        if (!ec) {
            boost::system::error_code ignored2;
            d->socket.close(ignored2);  // silent for too long: drop
        }
    });
    if (!options_.tls) {
        read_head(std::move(d));
        return;
    }
    // TLS on this port: a ClientHello starts with 0x16 (handshake record). Peek at the first byte without
    // consuming it, so that OpenSSL reads the whole record from the socket.
    auto self = shared_from_this();
    d->socket.async_wait(tcp::socket::wait_read, [d, self](boost::system::error_code ec) {
        if (ec) return;
        std::array<std::byte, 1> first{};
        boost::system::error_code ec2;
        const std::size_t n = d->socket.receive(asio::buffer(first), tcp::socket::message_peek, ec2);
        if (ec2 || n == 0) {
            d->timer.cancel();
            d->socket.close(ec2);  // closed before sending anything
            return;
        }
        if (first[0] == std::byte{0x16}) {
            d->timer.cancel();  // from here the TLS handshake's own timeout applies
            if (!d->refused.empty()) {
                d->socket.close(ec2);  // over the per-address limit: no handshake (logged by on_limited)
                return;
            }
            auto info = accepted_info(d->socket);
            info.hold = d->hold;
            accept_direct_tls(std::move(d->socket), std::move(info), self->sink_, self->options_.tls);
            return;
        }
        self->read_head(d);
    });
}

void TcpListener::read_head(std::shared_ptr<Detect> d) {
    auto self = shared_from_this();
    asio::async_read(d->socket, asio::buffer(d->head), [d, self](boost::system::error_code ec, std::size_t) {
        d->timer.cancel();
        if (ec) return;
        const auto& h = d->head;
        if (!d->refused.empty()) {  // over the per-address limit (logged by on_limited)
            if (could_begin_http(h)) return refuse_http(std::move(d->socket), d->refused);
            boost::system::error_code ignored2;
            d->socket.close(ignored2);
            return;
        }
        std::vector<std::byte> initial(h.begin(), h.end());
        if (is_rrac(h)) {
            auto sink = self->sink_.lock();
            if (!sink) return;
            auto info = accepted_info(d->socket);
            info.hold = d->hold;
            if (self->options_.tls)  // STARTTLS (rrs+tcp) or plain RR: the first message decides
                accept_rr_or_starttls(std::move(d->socket), std::move(initial), std::move(info), self->sink_,
                                      self->options_.tls);
            else
                serve_stream(*sink, std::move(d->socket), info, std::move(initial));
        } else if (!could_begin_http(h)) {
            boost::system::error_code ignored2;
            d->socket.close(ignored2);  // neither RR nor HTTP (wrong magic, binary garbage): drop
        } else if (self->options_.tls && self->options_.tls->required) {
            // Plain HTTP on a port that requires TLS: say so and close.
            static constexpr char kTlsRequired[] =
                "HTTP/1.1 403 Forbidden\r\nConnection: close\r\nContent-Type: text/plain; charset=utf-8\r\n"
                "Content-Length: 50\r\n\r\nTLS required on this port: use https:// or wss://\n";
            auto sock = std::make_shared<tcp::socket>(std::move(d->socket));
            asio::async_write(*sock, asio::buffer(kTlsRequired, sizeof(kTlsRequired) - 1), [sock](boost::system::error_code, std::size_t) {
                boost::system::error_code ignored;
                sock->shutdown(tcp::socket::shutdown_send, ignored);
                sock->close(ignored);
            });
        } else if (self->options_.http) {
            // Anything else is HTTP (plain requests and WebSocket upgrades).
            self->options_.http(std::move(d->socket), std::move(initial), d->hold);
        } else {
            // Without an HTTP handler the node answers 404 and closes, as CORE does.
            static constexpr char kNotFound[] = "HTTP/1.1 404 File Not Found\r\nConnection: close\r\nContent-Length: 0\r\n\r\n";
            auto sock = std::make_shared<tcp::socket>(std::move(d->socket));
            asio::async_write(*sock, asio::buffer(kNotFound, sizeof(kNotFound) - 1), [sock](boost::system::error_code, std::size_t) {
                boost::system::error_code ignored;
                sock->close(ignored);
            });
        }
    });
}

}  // namespace rr::server
