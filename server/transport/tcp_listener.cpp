#include "server/transport/tcp_listener.hpp"

#include <array>

#include <boost/asio/read.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/write.hpp>

#include "server/node/node.hpp"

namespace rr::server {

namespace asio = boost::asio;
using tcp = asio::ip::tcp;

TcpListener::TcpListener(std::weak_ptr<Node> node, tcp::acceptor acceptor)
    : node_(std::move(node)), acceptor_(std::move(acceptor)) {}

void TcpListener::start() { accept(); }

void TcpListener::stop() {
    boost::system::error_code ignored;
    acceptor_.close(ignored);
}

std::uint16_t TcpListener::port() const {
    boost::system::error_code ec;
    auto ep = acceptor_.local_endpoint(ec);
    return ec ? 0 : ep.port();
}

void TcpListener::accept() {
    auto self = shared_from_this();
    acceptor_.async_accept(asio::make_strand(acceptor_.get_executor()),
                           [self](boost::system::error_code ec, tcp::socket socket) {
                               if (ec == asio::error::operation_aborted || !self->acceptor_.is_open()) return;
                               if (!ec) self->detect(std::move(socket));
                               self->accept();
                           });
}

void TcpListener::detect(tcp::socket socket) {
    auto node = node_.lock();
    if (!node) return;
    const auto& opts = node->options();
    if (opts.max_connections && node->connection_count() >= opts.max_connections) {
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
    d->timer.expires_after(opts.first_bytes_timeout);
    d->timer.async_wait([d](boost::system::error_code ec) {
        if (!ec) {
            boost::system::error_code ignored2;
            d->socket.close(ignored2);  // silent for too long: drop
        }
    });
    std::weak_ptr<Node> weak = node_;
    asio::async_read(d->socket, asio::buffer(d->head), [d, weak](boost::system::error_code ec, std::size_t) {
        d->timer.cancel();
        auto node = weak.lock();
        if (ec || !node) return;
        const auto& h = d->head;
        auto is = [&](const char* s) {
            for (int i = 0; i < 4; ++i)
                if (h[i] != static_cast<std::byte>(s[i])) return false;
            return true;
        };
        std::vector<std::byte> initial(h.begin(), h.end());
        if (is("RRAC")) {
            node->serve_stream(std::move(d->socket), std::move(initial));
        } else {
            // Anything else is HTTP (plain requests and WebSocket upgrades); without an HTTP handler the
            // node answers 404 and closes, as CORE does.
            node->dispatch_http(std::move(d->socket), std::move(initial));
        }
    });
}

}  // namespace rr::server
