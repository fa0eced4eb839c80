// The service side of one accepted connection: drives core's ServiceSession (core/session/
// service_session.hpp: the stream protocol, special requests, the client session and its operations)
// on the connection's strand, and connects its events to the Service the client chose: member requests
// to Service::handle_entry with a Responder, ObjectTypeName to Service::object_type, the session's
// opening and closing to on_session_open / on_session_close. Services reach their client from any
// thread through SessionRef (ServerSession here), which posts to the strand.
#pragma once

#include <atomic>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "core/session/service_session.hpp"
#include "server/node/service.hpp"
#include "server/node/service_registry.hpp"
#include "server/transport/connection_logic.hpp"
#include "server/transport/stream_pump.hpp"

namespace rr::server {

/// Node-wide traffic counters (for /metrics).
struct NodeStats {
    std::atomic<std::uint64_t> connections_total{0}, messages_in{0}, messages_out{0}, bytes_in{0}, bytes_out{0};
    std::atomic<std::size_t> connections_open{0};
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
    /// The client's address (AcceptedStream::peer), for services that rate-limit logins per address.
    std::string peer;
    /// AcceptedStream::web_login.
    std::string web_login;
};

class ServerConnection;

/// One client session (one client endpoint) on one connection, as services hold it (SessionRef).
/// Thread-safe.
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
    /// The same for an entry many sessions send unchanged (encoded once per message format).
    Result<void> send(std::shared_ptr<const EncodedEntry> entry);
    Result<void> send_wire_packet(std::shared_ptr<const EncodedEntry> entry);
    void request(MessageEntry entry, std::function<void(Result<MessageEntry>)> done);
    std::size_t queued_bytes() const noexcept { return queued_.load(); }
    void set_queued_bytes(std::size_t n) noexcept { queued_.store(n); }
    /// The connection's local_url() (empty once the connection is gone).
    std::string local_url() const;
    /// The connection's client address (ServerConnectionConfig::peer; empty once it is gone).
    std::string peer() const;
    /// SessionRef::set_liveness_probe: posted to the connection's strand.
    void set_liveness_probe(std::optional<std::chrono::milliseconds> timeout);

    /// A wire packet of this session's own, or one shared by many sessions.
    using PendingWire = std::variant<MessageEntry, std::shared_ptr<const EncodedEntry>>;
    /// A reply to one of this session's requests (Responder::respond from another thread).
    struct PendingReply {
        explicit PendingReply(MessageEntry&& e) : entry(std::move(e)) {}
        MessageEntry entry;
    };
    /// What other threads send, in the order they sent it: a shared entry, an entry of the session's
    /// own (send), a reply.
    using PendingSend = std::variant<std::shared_ptr<const EncodedEntry>, MessageEntry, PendingReply>;
    /// A reply from another thread, queued in order with the session's sends for the pump's one wake
    /// (no closure per reply). Only when the pump knows it is off its strand (known_off_strand);
    /// otherwise the connection's reply sink dispatches it.
    void queue_reply(MessageEntry&& reply);
    /// Strand side: moves what other threads queued for the pump's wake into `sends` (in the order
    /// sent) and `wires` (the newest unsent packet of every (service path, member), in key order),
    /// both appended. What is queued after this wakes the pump again.
    void take_queued(std::vector<PendingSend>& sends, std::vector<PendingWire>& wires);

private:
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
    // What other threads queued for the strand: sends and replies in order (sends bounded by
    // max_queue_, replies by the requests in flight), and wire packets, newest per (service path,
    // member). A wire slot stays when its packet is taken (no map node per packet), unless there are
    // more than kKeptWireSlots. `wake_pending_`: the pump was woken for them and has not taken them
    // yet (one wake for all).
    static constexpr std::size_t kKeptWireSlots = 64;
    std::vector<PendingSend> send_pending_;
    std::map<std::pair<std::string, std::string>, std::optional<PendingWire>> wire_pending_;
    bool wake_pending_ = false;
    Result<void> queue_wire_packet(std::pair<std::string, std::string> key, PendingWire packet);
    template <class T, class Arg>
    void queue_send(PumpHandle& pump, std::in_place_type_t<T> kind, Arg&& arg);  // built in place: no move
};

class ServerConnection : public ConnectionLogic, public std::enable_shared_from_this<ServerConnection> {
public:
    /// `local_url`: base URL of the accepting listener, reported by SessionRef::local_url().
    ServerConnection(std::shared_ptr<ServiceRegistry> services, std::shared_ptr<NodeStats> stats,
                     ServerConnectionConfig config, std::string local_url, MonoTime now);
    ~ServerConnection() override;

    const std::string& local_url() const noexcept { return local_url_; }
    const std::string& peer() const noexcept { return config_.peer; }
    /// On the strand: ServiceSession::set_liveness_probe at the time now.
    void set_liveness_probe(std::optional<std::chrono::milliseconds> timeout);

    // ConnectionLogic
    void attach(std::weak_ptr<PumpHandle> pump) override { pump_ = std::move(pump); }
    void on_bytes(std::span<const std::byte> bytes, MonoTime now) override;
    bool has_output() const override { return session_.pending_output_size() != 0; }
    void take_output(GatherBuffer& out) override;
    std::span<std::byte> read_space() override { return session_.read_space(); }
    std::optional<MonoTime> next_deadline() const override { return session_.next_deadline(); }
    void on_timer(MonoTime now) override;
    bool wants_close() const override { return session_.is_closed(); }
    bool wants_read() const override { return session_.pending_output_size() < config_.read_pause_bytes; }
    /// Sends what the client session queued from other threads (ServerSession::send,
    /// send_wire_packet, queue_reply).
    void on_wake() override;
    void on_transport_closed(RRError error) override;

    // Strand-side operations used by ServerSession and Responder.
    void send_session_entry(MessageEntry&& entry);
    void send_session_entry(const EncodedEntry& entry);
    void send_session_request(MessageEntry entry, std::function<void(Result<MessageEntry>)> done);
    void reply(MessageEntry&& entry);

private:
    void drain_events();
    void handle_event(ServiceSessionEvent& event);
    void on_request(ServiceRequest& request);
    void on_admission(ServiceAdmission&& admission);
    void on_object_type_query(ServiceObjectTypeQuery&& query);
    Responder make_responder(const MessageEntry& request);
    void update_queue_estimate();
    void send_entry(MessageEntry&& entry, MonoTime now);  // send_session_entry without drain_events
    class ConnectionReplySink;

    std::shared_ptr<ServiceRegistry> services_;
    std::shared_ptr<NodeStats> stats_;
    ServerConnectionConfig config_;
    std::string local_url_;
    ServiceSession session_;
    std::weak_ptr<PumpHandle> pump_;
    std::shared_ptr<ReplySink> reply_sink_;    // the open session's; made on its first request
    std::shared_ptr<ServerSession> current_;  // the open client session's handle, if any
    std::map<std::uint32_t, std::function<void(Result<MessageEntry>)>> callbacks_;
    std::uint64_t messages_in_seen_ = 0, messages_out_seen_ = 0;
    std::vector<ServiceSessionEvent> batch_;  // drain_events' (only the outermost call uses it)
    // on_wake's, kept for their capacity.
    std::vector<ServerSession::PendingSend> woken_sends_;
    std::vector<ServerSession::PendingWire> woken_wires_;
    bool draining_ = false;
};

}  // namespace rr::server
