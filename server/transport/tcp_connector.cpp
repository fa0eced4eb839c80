#include "server/transport/tcp_connector.hpp"

#include <memory>

#include <boost/asio/connect.hpp>
#include <boost/asio/steady_timer.hpp>

#include "core/session/client_session.hpp"

namespace rr::server {

namespace asio = boost::asio;
using tcp = asio::ip::tcp;

void connect_tcp(asio::any_io_executor executor, const std::string& host, std::uint16_t port,
                 std::chrono::milliseconds timeout, std::function<void(Result<tcp::socket>)> done) {
    struct Op {
        tcp::resolver resolver;
        tcp::socket socket;
        asio::steady_timer timer;
        std::function<void(Result<tcp::socket>)> done;
        bool finished = false;
        std::string where;
        std::string limit;
        void finish(Result<tcp::socket> r) {
            if (finished) return;
            finished = true;
            timer.cancel();
            done(std::move(r));
        }
    };
    auto op = std::make_shared<Op>(Op{tcp::resolver(executor), tcp::socket(executor), asio::steady_timer(executor),
                                      std::move(done), false, host + ":" + std::to_string(port), seconds_text(timeout)});
    op->timer.expires_after(timeout);
    op->timer.async_wait([op](boost::system::error_code ec) {
        if (ec || op->finished) return;
        boost::system::error_code ignored;
        op->resolver.cancel();
        op->socket.close(ignored);
        op->finish(fail(MessageErrorType::ConnectionError, "connect to " + op->where + " timed out after " + op->limit));
    });
    op->resolver.async_resolve(host, std::to_string(port), [op](boost::system::error_code ec, tcp::resolver::results_type results) {
        if (op->finished) return;
        if (ec) {
            op->finish(fail(MessageErrorType::ConnectionError, "cannot resolve " + op->where + ": " + ec.message()));
            return;
        }
        asio::async_connect(op->socket, results, [op](boost::system::error_code ec2, const tcp::endpoint&) {
            if (op->finished) return;
            if (ec2) {
                op->finish(fail(MessageErrorType::ConnectionError, "cannot connect to " + op->where + ": " + ec2.message()));
                return;
            }
            boost::system::error_code ignored;
            op->socket.set_option(tcp::no_delay(true), ignored);
            op->finish(std::move(op->socket));
        });
    });
}

}  // namespace rr::server

namespace rr::server {

void TcpConnector::connect(asio::any_io_executor strand, const ConnectionUrl& url, const ConnectOptions& options,
                           std::shared_ptr<ConnectionLogic> logic, ConnectHandler done) {
    connect_tcp(strand, url.host, url.port, options.connect_timeout,
                [strand, logic = std::move(logic), done = std::move(done)](Result<tcp::socket> socket) mutable {
                    if (!socket) return done(socket.take_error());
                    start_client_stream(std::move(*socket), strand, std::move(logic), done);
                });
}

}  // namespace rr::server
