// RobotRaconteurNode: a NodeID and NodeName, an Asio executor with worker threads, transports
// (TCP listener and connector), registered services, and endpoint ids. The only owner of threads in
// the server room.
#pragma once

#include <atomic>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>

#include "server/service/server_connection.hpp"

namespace rr::server {

struct NodeOptions {
    NodeID node_id;         ///< all-zero: a random NodeID is generated
    std::string node_name;  ///< may be empty
    unsigned threads = 0;   ///< worker threads; 0 = hardware concurrency (at least 2)
    ServerConnectionConfig server;
    /// Accepted connections at once; 0 = unlimited (wire.md §13).
    std::size_t max_connections = 0;
    /// How long an accepted socket may take to send its first 4 bytes (wire.md §6.1: 5 s).
    std::chrono::milliseconds first_bytes_timeout{5000};
};

/// Hands over a socket whose first bytes were `GET ` (an HTTP request: WebSocket upgrade or plain HTTP).
using HttpHandler = std::function<void(boost::asio::ip::tcp::socket socket, std::vector<std::byte> initial)>;

class TcpListener;

/// `rr+tcp://<address>:<port>/` for a local TCP endpoint (IPv6 in brackets, without scope), the base of
/// the URLs the service index reports (wire.md §11.2).
std::string tcp_base_url(const boost::asio::ip::tcp::endpoint& local);

class Node : public NodeServices, public std::enable_shared_from_this<Node> {
public:
    static std::shared_ptr<Node> create(NodeOptions options = {});
    ~Node() override;
    Node(const Node&) = delete;
    Node& operator=(const Node&) = delete;

    boost::asio::io_context& io_context() noexcept { return io_; }
    const NodeOptions& options() const noexcept { return options_; }

    /// Listens for TCP connections (raw RR, and HTTP when an HttpHandler is set) on `address:port`
    /// (port 0 = ephemeral). Returns the bound port. Errors: IOError with the system message.
    Result<std::uint16_t> listen_tcp(const std::string& address, std::uint16_t port);
    /// Where sockets starting with `GET ` go (set before listening; default: answer 404 and close).
    void set_http_handler(HttpHandler handler);

    /// Registers a service under its name. Errors: InvalidArgument when the name is taken or invalid.
    Result<void> register_service(std::shared_ptr<Service> service);
    void unregister_service(const std::string& name);
    /// Names of the registered services (the built-in service index is not among them).
    std::vector<std::string> service_names() const;
    /// Base URL for connections whose transport gave none (WebSocket): the first TCP listener's.
    std::string listen_base_url() const;

    /// Serves an already-connected stream (used by transports other than TCP: WebSocket, local).
    /// `initial` are bytes already read from it.
    template <class Stream>
    void serve_stream(Stream stream, std::vector<std::byte> initial = {});
    /// Like serve_stream(), with the base URL the service index reports for connections that came in
    /// this way (wire.md §11.2), e.g. "rr+local:///" for a Unix socket; "" = listen_base_url().
    template <class Stream>
    void serve_stream_as(Stream stream, std::string local_url, std::vector<std::byte> initial = {});

    /// Stops listening, closes every connection and joins the worker threads. Idempotent.
    void shutdown();

    // NodeServices
    const NodeID& node_id() const override { return options_.node_id; }
    const std::string& node_name() const override { return options_.node_name; }
    /// A registered service, else for `RobotRaconteurServiceIndex` the node's built-in service index
    /// (service_index.hpp), as every CORE node serves it (wire.md §11.2).
    std::shared_ptr<Service> find_service(std::string_view name) const override;
    std::uint32_t new_endpoint_id() override;
    void release_endpoint_id(std::uint32_t id) override;
    std::shared_ptr<NodeStats> stats() const override { return stats_; }

    /// Connections currently open (accepted).
    std::size_t connection_count() const noexcept { return connections_->load(); }

private:
    explicit Node(NodeOptions options);
    void start_threads();
    void dispatch_http(boost::asio::ip::tcp::socket socket, std::vector<std::byte> initial);

    NodeOptions options_;
    boost::asio::io_context io_;
    std::unique_ptr<boost::asio::executor_work_guard<boost::asio::io_context::executor_type>> work_;
    std::vector<std::thread> threads_;
    std::vector<std::shared_ptr<TcpListener>> listeners_;
    HttpHandler http_handler_;
    mutable std::mutex mutex_;
    std::map<std::string, std::shared_ptr<Service>, std::less<>> services_;
    std::shared_ptr<Service> service_index_;  // set once in create()
    std::vector<boost::asio::ip::tcp::endpoint> listen_endpoints_;
    std::set<std::uint32_t> endpoints_;
    std::shared_ptr<std::atomic<std::size_t>> connections_ = std::make_shared<std::atomic<std::size_t>>(0);
    std::vector<std::weak_ptr<PumpHandle>> pumps_;  // for shutdown; pruned as connections come and go
    std::shared_ptr<NodeStats> stats_ = std::make_shared<NodeStats>();
    void track(const std::shared_ptr<PumpHandle>& pump);
    std::atomic<bool> stopped_{false};
    friend class TcpListener;
};

}  // namespace rr::server

#include "server/node/node_impl.hpp"
