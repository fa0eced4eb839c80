// RobotRaconteurNode: a NodeID and NodeName, an Asio executor with worker threads, the services it
// hosts (ServiceRegistry), the listeners that bring connections to them, and the connectors its own
// clients use (TransportRegistry). The only owner of threads in the server room.
//
// Transports plug in through server/transport/transport.hpp: a listener hands accepted byte streams to
// the node (a ConnectionSink), which runs a ServerConnection (core's ServiceSession) over each.
#pragma once

#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/io_context.hpp>

#include "server/node/server_connection.hpp"
#include "server/node/service.hpp"
#include "server/node/service_registry.hpp"
#include "server/transport/transport.hpp"
#include "server/transport/transport_registry.hpp"

namespace rr::server {

class AddressLimiter;

struct NodeOptions {
    NodeID node_id;         ///< all-zero: a random NodeID is generated
    std::string node_name;  ///< may be empty
    unsigned threads = 0;   ///< worker threads; 0 = hardware concurrency (at least 2)
    ServerConnectionConfig server;
    /// Accepted connections at once; 0 = unlimited (wire.md §13).
    std::size_t max_connections = 0;
    /// How long an accepted TCP socket may take to send its first 4 bytes (wire.md §6.1: 5 s).
    std::chrono::milliseconds first_bytes_timeout{5000};
    /// Open connections per client IP address on TCP listeners (nullptr: no limit; TcpListenerOptions).
    std::shared_ptr<AddressLimiter> address_limiter;
    /// Told about each connection the limiter refuses (address, reason), e.g. to log it. Optional.
    std::function<void(const std::string& address, const std::string& reason)> on_limited;
    /// Messages/s and bytes/s each accepted connection may send (all 0: unpaced). A connection over
    /// its rate has its reads paused (ReadThrottle); it is not closed.
    ReadRates read_rates;
    /// Told each time a connection's reads are paused for going over read_rates (peer). Optional.
    std::function<void(const std::string& peer)> on_throttled;
};

class Node : public ConnectionSink, public std::enable_shared_from_this<Node> {
public:
    static std::shared_ptr<Node> create(NodeOptions options = {});
    ~Node() override;
    Node(const Node&) = delete;
    Node& operator=(const Node&) = delete;

    boost::asio::io_context& io_context() noexcept { return io_; }
    const NodeOptions& options() const noexcept { return options_; }
    const NodeID& node_id() const noexcept { return options_.node_id; }
    const std::string& node_name() const noexcept { return options_.node_name; }

    /// Connectors for this node's own clients (the gateway's devices), by URL scheme; starts with the
    /// built-in transports.
    TransportRegistry& transports() noexcept { return transports_; }

    /// Adds a listener of any transport (opened on io_context() with this node as its sink: see
    /// listen_tcp() in server/transport/tcp_listener.hpp, listen_local() in local/local_listener.hpp):
    /// it is stopped at shutdown and its URLs are reported by listen_urls().
    void add_listener(std::shared_ptr<Listener> listener);
    /// Base URLs of every listener, in the order they were added.
    std::vector<std::string> listen_urls() const;
    /// Base URL for connections whose transport gave none: the first TCP listener's.
    std::string listen_base_url() const;
    /// Adds a callback run after every register_service / unregister_service (on that thread, no lock
    /// held), after the ServiceStateNonce was renewed: discovery announces the new one there.
    void on_services_changed(std::function<void()> callback);
    /// The node's ServiceStateNonce (wire.md §11.1; CORE RobotRaconteurNode::GetServiceStateNonce): 16
    /// characters, renewed whenever a service is registered or removed. The node has one: its UDP
    /// announces and its rr+local entries carry the same value, so clients re-read its services when it
    /// changes, whichever way they found the node. Thread-safe.
    std::string service_state_nonce() const;

    /// Registers a service under its name. Errors: InvalidArgument when the name is taken or invalid.
    Result<void> register_service(std::shared_ptr<Service> service);
    void unregister_service(const std::string& name);
    /// Names of the registered services (the built-in service index is not among them).
    std::vector<std::string> service_names() const;
    /// A registered service, else for `RobotRaconteurServiceIndex` the node's built-in service index
    /// (service_index.hpp), as every CORE node serves it (wire.md §11.2).
    std::shared_ptr<Service> find_service(std::string_view name) const;

    /// A local endpoint id of this node's numbering for a session that no connection opens (the
    /// gateway's JSON API device logins), so it never equals a connected client's; release it after.
    std::uint32_t allocate_endpoint() { return services_->allocate_endpoint(); }
    void release_endpoint(std::uint32_t endpoint) { services_->release_endpoint(endpoint); }

    /// Stops listening, closes every connection and joins the worker threads. Idempotent.
    void shutdown();

    std::shared_ptr<NodeStats> stats() const { return stats_; }
    /// Connections currently open (accepted, any transport).
    std::size_t connection_count() const noexcept { return stats_->connections_open.load(); }

    // ConnectionSink
    std::shared_ptr<ConnectionLogic> open_connection(const AcceptedStream& stream) override;
    void track(const std::shared_ptr<PumpHandle>& pump) override;
    bool can_accept() const override;
    std::unique_ptr<ReadThrottle> make_read_throttle() override;
    void read_throttled(const std::string& peer) override;
    /// Times a connection's reads were paused for going over NodeOptions::read_rates.
    std::uint64_t reads_throttled() const noexcept { return reads_throttled_.load(std::memory_order_relaxed); }

private:
    explicit Node(NodeOptions options);
    void start_threads();
    void services_changed();

    NodeOptions options_;
    boost::asio::io_context io_;
    std::unique_ptr<boost::asio::executor_work_guard<boost::asio::io_context::executor_type>> work_;
    std::vector<std::thread> threads_;
    std::shared_ptr<ServiceRegistry> services_ = std::make_shared<ServiceRegistry>();
    std::shared_ptr<Service> service_index_;  // set once in create()
    TransportRegistry transports_;
    mutable std::mutex mutex_;
    std::vector<std::shared_ptr<Listener>> listeners_;
    std::vector<std::weak_ptr<PumpHandle>> pumps_;  // for shutdown; pruned as connections come and go
    std::shared_ptr<NodeStats> stats_ = std::make_shared<NodeStats>();
    std::vector<std::function<void()>> services_changed_callbacks_;
    std::string service_state_nonce_;  // guarded by mutex_
    std::atomic<bool> stopped_{false};
    std::atomic<std::uint64_t> reads_throttled_{0};
};

}  // namespace rr::server
