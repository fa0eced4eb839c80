// The strand each accepted connection runs on (its socket's executor, its pump's strand).
#pragma once

#include <boost/asio/any_io_executor.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/strand.hpp>

namespace rr::server {

/// A new strand over `executor`, type-erased as sockets and Beast want it. Over an io_context's own
/// executor (the node's) the strand is built on the concrete executor type: each handler it runs is then
/// queued to the io_context directly instead of through a second type-erased executor, which wrapped
/// every handler in one more heap object (issue 14, bench/profile.sh).
inline boost::asio::any_io_executor connection_strand(const boost::asio::any_io_executor& executor) {
    if (const auto* io = executor.target<boost::asio::io_context::executor_type>()) return boost::asio::make_strand(*io);
    return boost::asio::make_strand(executor);
}

}  // namespace rr::server
