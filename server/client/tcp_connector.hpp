// Opens a TCP connection for a client: resolve, connect with a timeout (wire.md §13: 5 s), TCP_NODELAY.
#pragma once

#include <chrono>
#include <functional>
#include <string>

#include <boost/asio/ip/tcp.hpp>

#include "core/error/rr_error.hpp"

namespace rr::server {

/// Calls `done` once with the connected socket or an error (ConnectionError naming host:port and
/// the system message, or ConnectionError "connect timed out").
void connect_tcp(boost::asio::any_io_executor executor, const std::string& host, std::uint16_t port,
                 std::chrono::milliseconds timeout,
                 std::function<void(Result<boost::asio::ip::tcp::socket>)> done);

}  // namespace rr::server
