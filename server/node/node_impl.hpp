// Template part of Node.
#pragma once

#include <boost/asio/strand.hpp>

#include "server/transport/stream_pump.hpp"

namespace rr::server {

/// ServerConnection plus the node's connection count (a shared counter, so no reference to the node
/// is kept: connections live inside the node's io_context).
class CountedServerConnection : public ServerConnection {
public:
    CountedServerConnection(const std::shared_ptr<Node>& node, std::shared_ptr<std::atomic<std::size_t>> counter,
                            ServerConnectionConfig config, MonoTime now)
        : ServerConnection(node, std::move(config), now), counter_(std::move(counter)) {
        counter_->fetch_add(1);
        node->stats()->connections_total.fetch_add(1, std::memory_order_relaxed);
    }
    ~CountedServerConnection() override { counter_->fetch_sub(1); }

private:
    std::shared_ptr<std::atomic<std::size_t>> counter_;
};

template <class Stream>
void Node::serve_stream(Stream stream, std::vector<std::byte> initial) {
    std::string local_url;
    if constexpr (requires(boost::system::error_code& ec) { tcp_base_url(stream.local_endpoint(ec)); }) {
        boost::system::error_code ec;
        auto local = stream.local_endpoint(ec);
        if (!ec) local_url = tcp_base_url(local);
    }
    serve_stream_as(std::move(stream), std::move(local_url), std::move(initial));
}

template <class Stream>
void Node::serve_stream_as(Stream stream, std::string local_url, std::vector<std::byte> initial) {
    // The stream's executor is a per-connection strand (TcpListener accepts onto one); the pump uses it
    // as its own, so whatever the stream does internally (a WebSocket's control frames) is serialised
    // with the pump's work.
    typename StreamPump<Stream>::Strand strand(stream.get_executor());
    auto logic = std::make_shared<CountedServerConnection>(shared_from_this(), connections_, options_.server, mono_now());
    if (!local_url.empty()) logic->set_local_url(std::move(local_url));
    auto pump = std::make_shared<StreamPump<Stream>>(std::move(stream), strand, logic);
    logic->attach(pump);
    track(pump);
    pump->start(initial);
}

}  // namespace rr::server
