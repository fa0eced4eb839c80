// rr+tcp, client side: resolve, connect with a timeout (wire.md §13: 5 s), TCP_NODELAY, then a
// StreamPump over the socket. Also answers the legacy `tcp://` scheme.
#pragma once

#include <chrono>
#include <functional>
#include <string>

#include <boost/asio/ip/tcp.hpp>

#include "base/error/rr_error.hpp"
#include "server/transport/transport.hpp"

namespace rr::server {

/// Calls `done` once with the connected socket or an error (ConnectionError naming host:port and
/// the system message, or ConnectionError "connect to host:port timed out after S s").
void connect_tcp(boost::asio::any_io_executor executor, const std::string& host, std::uint16_t port,
                 std::chrono::milliseconds timeout,
                 std::function<void(Result<boost::asio::ip::tcp::socket>)> done);

class TcpConnector : public Connector {
public:
    void connect(boost::asio::any_io_executor strand, const ConnectionUrl& url, const ConnectOptions& options,
                 std::shared_ptr<ConnectionLogic> logic, ConnectHandler done) override;
};

}  // namespace rr::server
