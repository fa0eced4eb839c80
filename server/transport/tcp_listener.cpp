#include "server/transport/tcp_listener.hpp"

#include <array>
#include <string_view>

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

Result<std::shared_ptr<TcpListener>> TcpListener::open(asio::any_io_executor executor, const std::string& address,
                                                       std::uint16_t port, std::weak_ptr<ConnectionSink> sink,
                                                       TcpListenerOptions options) {
    boost::system::error_code ec;
    auto addr = asio::ip::make_address(address, ec);
    if (ec) return fail(MessageErrorType::InvalidArgument, "bad listen address \"" + address + "\": " + ec.message());
    tcp::acceptor acceptor(executor);
    tcp::endpoint ep(addr, port);
    acceptor.open(ep.protocol(), ec);
    if (!ec) acceptor.set_option(tcp::acceptor::reuse_address(true), ec);
    if (!ec) acceptor.bind(ep, ec);
    if (!ec) acceptor.listen(asio::socket_base::max_listen_connections, ec);
    if (ec)
        return fail(MessageErrorType::IOError, "cannot listen on " + address + ":" + std::to_string(port) + ": " + ec.message());
    return std::shared_ptr<TcpListener>(new TcpListener(std::move(acceptor), std::move(sink), std::move(options)));
}

TcpListener::TcpListener(tcp::acceptor acceptor, std::weak_ptr<ConnectionSink> sink, TcpListenerOptions options)
    : acceptor_(std::move(acceptor)), sink_(std::move(sink)), options_(std::move(options)) {
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
    acceptor_.async_accept(asio::make_strand(acceptor_.get_executor()), [self](boost::system::error_code ec, tcp::socket socket) {
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

    struct Detect {
        tcp::socket socket;
        asio::steady_timer timer;
        std::array<std::byte, 4> head{};
    };
    auto d = std::make_shared<Detect>(Detect{std::move(socket), asio::steady_timer(socket.get_executor()), {}});
    d->timer.expires_after(options_.first_bytes_timeout);
    d->timer.async_wait([d](boost::system::error_code ec) {
        if (!ec) {
            boost::system::error_code ignored2;
            d->socket.close(ignored2);  // silent for too long: drop
        }
    });
    auto self = shared_from_this();
    asio::async_read(d->socket, asio::buffer(d->head), [d, self](boost::system::error_code ec, std::size_t) {
        d->timer.cancel();
        if (ec) return;
        const auto& h = d->head;
        std::vector<std::byte> initial(h.begin(), h.end());
        static constexpr char kMagic[] = "RRAC";
        bool rr = true;
        for (int i = 0; i < 4; ++i) rr = rr && h[i] == static_cast<std::byte>(kMagic[i]);
        if (rr) {
            auto sink = self->sink_.lock();
            if (!sink) return;
            boost::system::error_code ec2;
            AcceptedStream info;
            auto local = d->socket.local_endpoint(ec2);
            if (!ec2) info.local_url = tcp_base_url(local);
            auto remote = d->socket.remote_endpoint(ec2);
            if (!ec2) info.peer = remote.address().to_string() + ":" + std::to_string(remote.port());
            serve_stream(*sink, std::move(d->socket), info, std::move(initial));
        } else if (!could_begin_http(h)) {
            boost::system::error_code ignored2;
            d->socket.close(ignored2);  // neither RR nor HTTP (wrong magic, binary garbage): drop
        } else if (self->options_.http) {
            // Anything else is HTTP (plain requests and WebSocket upgrades).
            self->options_.http(std::move(d->socket), std::move(initial));
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
