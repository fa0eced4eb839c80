// The server side of one accepted transport connection: the basic stream protocol (through core's
// StreamConnection), the node's special requests (wire.md §6.4: GetServiceDesc, ObjectTypeName,
// ConnectClient, ConnectClientCombined, DisconnectClient, GetNodeInfo, NodeCheckCapability,
// GetServiceAttributes), the at most one client session this connection carries, session operations
// (keep-alive, capability checks, AuthenticateUser/LogoutUser, object locks) and the hand-off of member
// requests to the Service. Runs on the connection's strand only (see StreamPump).
#pragma once

#include <atomic>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "core/session/stream_connection.hpp"
#include "server/node/connection_logic.hpp"
#include "server/service/service.hpp"
#include "server/transport/stream_pump.hpp"

namespace rr::server {

/// Node-wide traffic counters (for /metrics).
struct NodeStats {
    std::atomic<std::uint64_t> connections_total{0}, messages_in{0}, messages_out{0}, bytes_in{0}, bytes_out{0};
};

/// What a connection needs from its node. Implemented by Node; thread-safe.
class NodeServices {
public:
    virtual ~NodeServices() = default;
    virtual const NodeID& node_id() const = 0;
    virtual const std::string& node_name() const = 0;
    virtual std::shared_ptr<Service> find_service(std::string_view name) const = 0;
    /// A fresh, non-zero endpoint id unused in this node.
    virtual std::uint32_t new_endpoint_id() = 0;
    virtual void release_endpoint_id(std::uint32_t id) = 0;
    virtual std::shared_ptr<NodeStats> stats() const = 0;
};

/// Per-connection settings.
struct ServerConnectionConfig {
    StreamConfig stream;
    /// Non-reply traffic (events, pipe packets) queued for one client beyond this is refused with
    /// BufferLimitViolation; wire packets are held back (newest kept) above `wire_hold_bytes`.
    std::size_t max_send_queue_bytes = 8u * 1024u * 1024u;
    std::size_t wire_hold_bytes = 256u * 1024u;
    /// Stop reading requests from a client while this many bytes of output wait for it (it is not
    /// reading its replies); resume when they drain.
    std::size_t read_pause_bytes = 4u * 1024u * 1024u;
    std::chrono::milliseconds callback_timeout{15000};
};

class ServerConnection;

/// One client session (one client endpoint) on one connection. Shared with services via SessionRef.
class ServerSession : public std::enable_shared_from_this<ServerSession> {
public:
    ServerSession(std::uint32_t endpoint, std::uint32_t client_endpoint, std::shared_ptr<Service> service,
                  std::weak_ptr<PumpHandle> pump, std::weak_ptr<ServerConnection> connection, std::size_t max_queue);

    std::uint32_t endpoint() const noexcept { return endpoint_; }
    std::uint32_t client_endpoint() const noexcept { return client_endpoint_; }
    const std::shared_ptr<Service>& service() const noexcept { return service_; }
    std::string username() const;
    void set_username(std::string name);
    bool alive() const noexcept { return alive_.load(); }
    void mark_closed() noexcept { alive_.store(false); }

    Result<void> send(MessageEntry entry);
    Result<void> send_wire_packet(MessageEntry entry);
    void request(MessageEntry entry, std::function<void(Result<MessageEntry>)> done);
    std::size_t queued_bytes() const noexcept { return queued_.load(); }
    void set_queued_bytes(std::size_t n) noexcept { queued_.store(n); }
    /// The connection's local_url() (empty once the connection is gone).
    std::string local_url() const;

private:
    friend class ServerConnection;
    const std::uint32_t endpoint_;
    const std::uint32_t client_endpoint_;
    const std::shared_ptr<Service> service_;
    const std::weak_ptr<PumpHandle> pump_;
    const std::weak_ptr<ServerConnection> connection_;
    const std::size_t max_queue_;
    std::atomic<bool> alive_{true};
    std::atomic<std::size_t> queued_{0};
    mutable std::mutex mutex_;
    std::string username_;
    // Wire packets waiting to be posted to the strand, newest per (service path, member).
    std::map<std::pair<std::string, std::string>, MessageEntry> wire_pending_;
};

class ServerConnection : public ConnectionLogic, public std::enable_shared_from_this<ServerConnection> {
public:
    ServerConnection(const std::shared_ptr<NodeServices>& node, ServerConnectionConfig config, MonoTime now);
    ~ServerConnection() override;

    /// Must be called once the pump exists, before bytes flow.
    void attach(std::weak_ptr<PumpHandle> pump) { pump_ = std::move(pump); }
    /// Base URL of the accepting transport (SessionRef::local_url); set before bytes flow, then fixed.
    void set_local_url(std::string url) { local_url_ = std::move(url); }
    const std::string& local_url() const noexcept { return local_url_; }

    // ConnectionLogic
    void on_bytes(std::span<const std::byte> bytes, MonoTime now) override;
    bool has_output() const override { return stream_.pending_output_size() != 0; }
    void take_output(std::vector<std::byte>& out) override;
    std::optional<MonoTime> next_deadline() const override;
    void on_timer(MonoTime now) override;
    bool wants_close() const override { return stream_.is_closed() || close_after_flush_; }
    bool wants_read() const override { return stream_.pending_output_size() < config_.read_pause_bytes; }
    void on_transport_closed(RRError error) override;

    // Strand-side operations used by ServerSession / Responder.
    void send_session_entry(MessageEntry entry);
    void send_wire_entry(const std::pair<std::string, std::string>& key);
    void send_session_request(MessageEntry entry, std::function<void(Result<MessageEntry>)> done);

private:
    std::shared_ptr<Service> find_service(std::string_view name) const;
    void on_message(Message&& m, MonoTime now);
    void handle_special(const MessageHeader& h, MessageEntry&& e, MonoTime now);
    void handle_session_entry(const MessageHeader& h, MessageEntry&& e, MonoTime now);
    void handle_session_op(MessageEntry&& e, MonoTime now);
    void connect_client(const MessageHeader& h, MessageEntry&& e, bool combined, MonoTime now);
    void close_session();
    void reply_special(const MessageHeader& request_header, MessageEntry reply);
    void reply_session(MessageEntry reply);
    Responder make_responder(const MessageEntry& request);
    Message session_message(MessageEntry entry);
    void drain_events(MonoTime now);
    void update_queue_estimate();
    void flush_held_wires();

    std::weak_ptr<NodeServices> node_;  // weak: connections live inside the node's io_context
    std::shared_ptr<NodeStats> stats_;  // shared with the node, outlives it if need be
    NodeID node_id_;
    std::string node_name_;
    ServerConnectionConfig config_;
    StreamConnection stream_;
    std::weak_ptr<PumpHandle> pump_;
    std::string local_url_;
    std::shared_ptr<ServerSession> session_;
    bool authenticated_ = false;
    bool close_after_flush_ = false;
    std::uint16_t message_id_ = 0;
    std::uint32_t callback_request_counter_ = 0;
    struct PendingCallback {
        std::function<void(Result<MessageEntry>)> done;
        MonoTime deadline;
    };
    std::map<std::uint32_t, PendingCallback> pending_callbacks_;
    std::map<std::pair<std::string, std::string>, MessageEntry> held_wires_;
};

}  // namespace rr::server
