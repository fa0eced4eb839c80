// The client side of one RR client session over one transport connection, sans-IO, at the level of
// message entries (wire.md §6.4–§6.6): connect to a named service (ConnectClientCombined, or the legacy
// GetServiceDesc / ObjectTypeName / ConnectClient sequence with AuthenticateUser), request/response
// matching by RequestID with timeouts, ClientKeepAlive, DisconnectClient, and delivery of the entries
// the service sends unasked (events, pipe and wire packets, callback calls, released paths, service
// closed). Typed member access (values checked against the robdef) is layered on top in
// client_context.hpp.
//
// One connection carries exactly one client session (wire.md §6.4). Not thread-safe.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "core/session/event_queue.hpp"
#include "core/session/request_map.hpp"
#include "core/session/stream_connection.hpp"

namespace rr {

struct ClientSessionConfig {
    StreamConfig stream;
    std::string service_name;
    /// Optional credentials: username and password (sent as credentials {"password": …}).
    std::string username;
    std::string password;
    /// When set (and `username` is not empty), sent as the `credentials` element instead of
    /// {"password": password}: a gateway passes on what its own client sent, unchanged.
    std::optional<MessageElement> credentials;
    /// Per-request timeout (wire.md §13: 15 s).
    std::chrono::milliseconds request_timeout{15000};
    /// Bound on the whole connect, counted from construction: CreateConnection and the service connect
    /// exchange (ConnectClientCombined, or the legacy sequence) must be done by then, else the session
    /// closes with ConnectionError "connect timed out after S s: …". The host starts its transport
    /// (TCP connect, handshakes) after constructing the session, so one value bounds it all.
    /// 0 = no overall bound (only StreamConfig::connect_timeout and request_timeout per step).
    std::chrono::milliseconds connect_timeout{0};
    /// Send ClientKeepAliveReq after this long without sending (60 s).
    std::chrono::milliseconds keepalive_period{60000};
    /// The endpoint id of this client (random, non-zero); chosen by the host (core has no RNG).
    std::uint32_t local_endpoint = 1;
};

/// The service as described by the connect exchange.
struct ClientSessionInfo {
    std::string object_type;                    ///< qualified root object type
    std::vector<std::string> object_implements;  ///< qualified types the root implements
    std::vector<std::string> service_definitions;  ///< robdef texts: root's service first, then imports
    MessageElement attributes;                   ///< `attributes` (map string→varvalue) or void
};

/// Session established.
struct ClientSessionConnected {
    ClientSessionInfo info;
};
/// The answer to request(): the reply entry (whose Error field may be set), or a local error such as
/// RequestTimeout / ConnectionError.
struct ClientResponse {
    // Constructors, not aggregates: built in place in the event queue (see ServiceRequest).
    ClientResponse(std::uint32_t id, Result<MessageEntry>&& e) : request_id(id), entry(std::move(e)) {}
    ClientResponse(std::uint32_t id, MessageEntry&& e) : request_id(id), entry(std::move(e)) {}
    std::uint32_t request_id = 0;
    Result<MessageEntry> entry;
};
/// An entry the service sent without being asked: EventReq, PipePacket, PipePacketRet, PipeClosed,
/// WirePacket, WireClosed, CallbackCallReq (answer with reply()), ServicePathReleasedReq, ServiceClosed.
struct ClientIncoming {
    explicit ClientIncoming(MessageEntry&& e) : entry(std::move(e)) {}
    MessageEntry entry;
};
/// Session over; no further events follow.
struct ClientSessionClosed {
    RRError error;
};

using ClientSessionEvent = std::variant<ClientSessionConnected, ClientResponse, ClientIncoming, ClientSessionClosed>;

/// "2 s", "1.5 s", "0.25 s": a duration for messages.
std::string seconds_text(std::chrono::milliseconds d);

/// The error a client reports when the node has no service `service`: ServiceNotFound under its
/// standard name `RobotRaconteur.ServiceNotFound` (CORE puts the non-canonical
/// `RobotRaconteur.ServiceNotFoundException` on the wire, wire.md §5.1), with a message naming the
/// service; `remote_message` is kept in parentheses unless it is CORE's bare "Service not found" or
/// names the service already.
RRError service_not_found_error(std::string_view service, std::string_view remote_message);

class ClientSession {
public:
    ClientSession(ClientSessionConfig config, MonoTime now);

    // --- I/O pump (see StreamConnection) ---
    Result<void> feed(std::span<const std::byte> bytes, MonoTime now);
    /// See StreamConnection::read_space.
    std::span<std::byte> read_space() { return stream_.read_space(); }
    void on_transport_closed(RRError error);
    std::span<const std::byte> pending_output() const { return stream_.pending_output(); }
    void consume_output(std::size_t n) { stream_.consume_output(n); }
    void take_output(GatherBuffer& out) { stream_.take_output(out); }
    void take_output(std::vector<std::byte>& out) { stream_.take_output(out); }
    std::size_t pending_output_size() const noexcept { return stream_.pending_output_size(); }
    std::optional<MonoTime> next_deadline() const;
    void on_timer(MonoTime now);
    std::optional<ClientSessionEvent> poll_event();

    bool is_connected() const noexcept { return state_ == State::connected; }
    bool is_closed() const noexcept { return state_ == State::closed; }
    const ClientSessionInfo& info() const noexcept { return info_; }
    const StreamConnection& stream() const noexcept { return stream_; }

    /// Sends a request entry (RequestID assigned here) and returns the RequestID; the answer arrives
    /// as a ClientResponse. Errors: InvalidState when not connected; BufferLimitViolation.
    /// The sending functions take the entry by rvalue: it is moved once, into the outgoing message.
    Result<std::uint32_t> request(MessageEntry&& entry, MonoTime now);
    /// Like request() but with a per-request timeout (0 = none, e.g. generator Next on a long stream).
    Result<std::uint32_t> request(MessageEntry&& entry, MonoTime now, std::chrono::milliseconds timeout);
    /// Sends an entry that expects no answer (PipePacket, PipePacketRet, WirePacket).
    Result<void> send_packet(MessageEntry&& entry, MonoTime now);
    /// Answers a CallbackCallReq (the reply entry keeps the request's RequestID).
    Result<void> reply(MessageEntry&& entry, MonoTime now);
    /// Cancels waiting for a request: no ClientResponse will be delivered for it.
    void forget_request(std::uint32_t request_id);

    /// Sends DisconnectClient and closes once it is answered or after 500 ms (wire.md §6.6).
    void disconnect(MonoTime now);

    std::uint32_t local_endpoint() const noexcept { return config_.local_endpoint; }
    std::uint32_t remote_endpoint() const noexcept { return remote_endpoint_; }

private:
    enum class State : std::uint8_t {
        stream_connecting,
        combined_connect,   // waiting for ConnectClientCombinedRet
        legacy_servicedesc,  // waiting for GetServiceDescRet (root or an import)
        legacy_objecttype,
        legacy_connect,
        legacy_authenticate,
        connected,
        disconnecting,
        closed,
    };
    struct Pending {
        MonoTime deadline;
        bool has_deadline = true;
    };

    void drain_stream(MonoTime now);
    void on_stream_event(StreamEvent&& ev, MonoTime now);
    void on_message(Message&& m, MonoTime now);
    void on_entries(Message& m, MonoTime now);
    void on_connect_reply(MessageEntry&& e, const MessageHeader& h, MonoTime now);
    void start_connect(MonoTime now);
    Result<void> send_special(MessageEntry&& entry, MonoTime now, std::uint32_t receiver_endpoint = 0);
    Result<void> send_session(MessageEntry&& entry, MonoTime now);
    void request_missing_definitions(MonoTime now);
    void fail_connect(RRError error);
    void close(RRError error);
    std::uint32_t next_request_id();

    ClientSessionConfig config_;
    StreamConnection stream_;
    std::vector<StreamEvent> stream_batch_;  // drain_stream's
    State state_ = State::stream_connecting;
    ClientSessionInfo info_;
    std::uint32_t remote_endpoint_ = 0;
    std::uint32_t request_counter_ = 0;
    std::uint32_t connect_request_id_ = 0;
    std::uint16_t message_id_ = 0;
    std::vector<std::string> pending_imports_;
    RequestMap<Pending> pending_;
    EventQueue<ClientSessionEvent> events_;
    MonoTime last_send_;
    MonoTime connect_deadline_;
    std::optional<MonoTime> connect_limit_;  // construction + config_.connect_timeout, when set
    MonoTime disconnect_deadline_;
};

}  // namespace rr
