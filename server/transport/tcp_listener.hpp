// Accepts TCP connections and tells raw RR from HTTP by the first four bytes, as CORE's TcpTransport
// does (wire.md §6.1: `RRAC` → RR stream; `GET ` / `GET\t` → HTTP / WebSocket; anything else → 404 or
// close). Sockets get TCP_NODELAY.
#pragma once

#include <memory>

#include <boost/asio/ip/tcp.hpp>

namespace rr::server {

class Node;

class TcpListener : public std::enable_shared_from_this<TcpListener> {
public:
    TcpListener(std::weak_ptr<Node> node, boost::asio::ip::tcp::acceptor acceptor);
    void start();
    void stop();
    std::uint16_t port() const;

private:
    void accept();
    void detect(boost::asio::ip::tcp::socket socket);

    std::weak_ptr<Node> node_;
    boost::asio::ip::tcp::acceptor acceptor_;
};

}  // namespace rr::server
