// Presents a Beast WebSocket as a byte stream, so RR messages travel over it exactly as over TCP
// (wire.md §8): binary frames only, frame boundaries carry no meaning, at most 65 536 payload bytes per
// frame written (as CORE). A text frame from the peer is an error. Used by StreamPump.
// Beast's defaults would split every frame into 4 KiB fragments (auto_fragment) and mask a client's
// frames through a 4 KiB buffer: one write per 4 KiB. Here a frame goes out in one gathered write.
#pragma once

#include <algorithm>
#include <chrono>
#include <utility>

#include <boost/asio/associated_executor.hpp>
#include <boost/asio/bind_executor.hpp>
#include <boost/beast/core/buffers_prefix.hpp>
#include <boost/beast/core/stream_traits.hpp>
#include <boost/beast/websocket/stream.hpp>

namespace rr::server {

template <class NextLayer>
class WebSocketByteStream {
public:
    using websocket_type = boost::beast::websocket::stream<NextLayer>;
    using executor_type = typename websocket_type::executor_type;
    static constexpr std::size_t kMaxFramePayload = 65536;

    explicit WebSocketByteStream(websocket_type ws) : ws_(std::move(ws)) {
        ws_.binary(true);
        ws_.auto_fragment(false);
        ws_.write_buffer_bytes(kMaxFramePayload);  // client role: the masking buffer
    }

    executor_type get_executor() noexcept { return ws_.get_executor(); }

    template <class MutableBuffers, class Handler>
    void async_read_some(const MutableBuffers& buffers, Handler&& handler) {
        auto ex = boost::asio::get_associated_executor(handler, ws_.get_executor());
        ws_.async_read_some(buffers, boost::asio::bind_executor(
                                         ex, [this, h = std::forward<Handler>(handler)](boost::system::error_code ec,
                                                                                       std::size_t n) mutable {
                                             if (!ec && n > 0 && ws_.got_text())
                                                 ec = boost::asio::error::make_error_code(boost::asio::error::operation_not_supported);
                                             h(ec, n);
                                         }));
    }

    template <class ConstBuffers, class Handler>
    void async_write_some(const ConstBuffers& buffers, Handler&& handler) {
        ws_.async_write(boost::beast::buffers_prefix(kMaxFramePayload, buffers), std::forward<Handler>(handler));
    }

    /// Ends the WebSocket with a close frame: 1001 Going Away when `going_away` (the server is stopping),
    /// else 1000 Normal Closure; Beast then waits for the peer's close frame and closes the socket, and
    /// `handler(ec)` runs when that is over. Not bounded here: the stream's expiry cannot be changed while
    /// a read and a write are both pending (Beast asserts), so the caller bounds it (Node::shutdown closes
    /// every pump's socket after its moment: StreamPump::close_now).
    template <class Handler>
    void async_goodbye(bool going_away, Handler&& handler) {
        namespace websocket = boost::beast::websocket;
        ws_.async_close(going_away ? websocket::close_reason(websocket::close_code::going_away, "server stopping")
                                   : websocket::close_reason(websocket::close_code::normal),
                        std::forward<Handler>(handler));
    }

    auto& lowest_layer() noexcept { return boost::beast::get_lowest_layer(ws_).socket(); }
    websocket_type& websocket() noexcept { return ws_; }

private:
    websocket_type ws_;
};

}  // namespace rr::server
