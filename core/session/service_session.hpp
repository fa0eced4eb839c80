// The service side of one transport connection, sans-IO (wire.md §6.2–§6.6): the basic stream
// protocol (StreamConnection, server role), the node's special requests (GetServiceDesc,
// ObjectTypeName, ConnectClient, ConnectClientCombined, DisconnectClient, GetNodeInfo,
// NodeCheckCapability, GetServiceAttributes), the at most one client session the connection carries
// (endpoints, login state), the session operations (keep-alive, capability checks, AuthenticateUser,
// LogoutUser, monitor and object locks) and output policy (a reply over the size limit becomes an
// error reply; wire packets held back, newest kept, while output is backed up).
//
// What needs the service's own objects is handed to the host as an event: member requests and
// client-sent packets, ObjectTypeName for paths below the root, object lock operations, and the
// opening and closing of the client session. The host answers with reply(), answer_object_type(),
// and sends unsolicited entries with send(), send_wire_packet() and request() (callbacks).
//
// Bytes in: feed(). Bytes out: take_output(). Events out: poll_event(). Time: next_deadline() /
// on_timer(). Never reads a clock; not thread-safe (one owner drives it, e.g. a strand).
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "core/session/event_queue.hpp"
#include "core/session/service_host.hpp"
#include "core/session/stream_connection.hpp"

namespace rr {

struct ServiceSessionConfig {
    /// Stream settings; local_node_id and local_node_name are this node's.
    StreamConfig stream;
    /// Callback requests (request()) not answered in this time fail with RequestTimeout.
    std::chrono::milliseconds callback_timeout{15000};
    /// Wire packets are held back (newest per member kept) while more output than this waits.
    std::size_t wire_hold_bytes = 256u * 1024u;
    /// The client's address as the transport reported it ("ip:port", "local", …; "" = unknown): passed
    /// to HostedService::authenticate_from.
    std::string peer;
    /// A login the transport carried (the Cookie header of an rr+ws upgrade; "" = none): see
    /// HostedService::authenticate_web.
    std::string web_login;
};

/// The client session exists: `service` is the one the client connected to.
struct ServiceSessionOpened {
    std::shared_ptr<HostedService> service;
    std::uint32_t endpoint = 0;         ///< this node's endpoint for the session
    std::uint32_t client_endpoint = 0;  ///< the client's
    std::string username;               ///< set when the client logged in with the connect
};
/// The logged-in user changed (AuthenticateUser, LogoutUser): empty when none.
struct ServiceSessionUser {
    std::string username;
};
/// A member request (answer with reply()), a client-sent packet that needs no answer (PipePacket,
/// PipePacketRet, WirePacket: `needs_reply` false), or, for services whose handles_locks() is true, a
/// lock operation (ClientSessionOpReq with MemberName RequestObjectLock, RequestClientObjectLock,
/// ReleaseObjectLock, ReleaseClientObjectLock, MonitorEnter, MonitorContinueEnter, MonitorExit;
/// answer with reply()). A member request without elements may carry an empty element vector with
/// capacity, kept from an earlier reply: the service can build its reply in it.
/// The entry lives in an entry vector of its own: the received message's, when the request came alone
/// (the usual case: the entry stays where it was decoded), so the event costs no entry move. A host
/// hands the request back with ServiceSession::recycle once handled, so the next message reuses it.
struct ServiceRequest {
    // A constructor, not an aggregate: the event queue builds it in place (emplace with
    // in_place_type), which clang before 16 cannot do for an aggregate.
    /// `holder` has exactly one entry: the request.
    ServiceRequest(std::vector<MessageEntry>&& holder, bool reply) : entries(std::move(holder)), needs_reply(reply) {}
    MessageEntry& entry() noexcept { return entries.front(); }
    const MessageEntry& entry() const noexcept { return entries.front(); }
    std::vector<MessageEntry> entries;  ///< the request alone (empty once recycled)
    bool needs_reply = true;
};
/// ObjectTypeName for `path` in the session's service: answer with answer_object_type(token, …).
struct ServiceObjectTypeQuery {
    std::uint64_t token = 0;
    std::shared_ptr<HostedService> service;
    std::string path;
};
/// The client's answer to request() (CallbackCallRet), or RequestTimeout / ConnectionError.
struct ServiceCallbackResponse {
    // Built in place (as ServiceRequest): moving a temporary Result in made GCC 12 warn
    // -Wmaybe-uninitialized about the error side of the variant at -O3.
    ServiceCallbackResponse(std::uint32_t id, Result<MessageEntry>&& e) : request_id(id), entry(std::move(e)) {}
    std::uint32_t request_id = 0;
    Result<MessageEntry> entry;
};
/// A client asks for a session with a service whose admits_sessions() is true: answer with
/// answer_admission(token, …). `endpoint` is reserved for the session (ServiceSessionOpened carries the
/// same one when admitted). `username` / `credentials` are what ConnectClientCombined carried (empty /
/// nullopt when absent; a plain ConnectClient carries neither).
struct ServiceAdmission {
    std::uint64_t token = 0;
    std::shared_ptr<HostedService> service;
    std::uint32_t endpoint = 0;
    std::string username;
    std::optional<MessageElement> credentials;
};
/// The client session ended (DisconnectClient or the connection closed). No further session events.
/// `disconnect_token` is non-zero when the client's DisconnectClient ended a session of a service whose
/// admits_sessions() is true: its DisconnectClientRet is held until the host calls
/// answer_disconnect(disconnect_token, …), once the service has ended its side of the session.
struct ServiceSessionClosed {
    std::shared_ptr<HostedService> service;
    std::uint32_t endpoint = 0;
    std::uint64_t disconnect_token = 0;
};
/// The connection is closed: no further events.
struct ServiceConnectionClosed {
    RRError error;
};

using ServiceSessionEvent = std::variant<ServiceSessionOpened, ServiceSessionUser, ServiceRequest, ServiceObjectTypeQuery,
                                         ServiceCallbackResponse, ServiceSessionClosed, ServiceConnectionClosed,
                                         ServiceAdmission>;

class ServiceSession {
public:
    /// `host` must outlive the session (the node owns its connections' hosts).
    ServiceSession(ServiceHost& host, ServiceSessionConfig config, MonoTime now);
    ~ServiceSession();
    ServiceSession(const ServiceSession&) = delete;
    ServiceSession& operator=(const ServiceSession&) = delete;

    // --- I/O (see StreamConnection) ---
    /// Consumes all of `bytes`; a protocol error closes the connection (ServiceConnectionClosed).
    void feed(std::span<const std::byte> bytes, MonoTime now);
    /// See StreamConnection::read_space.
    std::span<std::byte> read_space() { return stream_.read_space(); }
    void on_transport_closed(RRError error);
    /// Moves the pending output into `out`: gathered (large payloads spliced, not copied) or contiguous.
    void take_output(GatherBuffer& out);
    void take_output(std::vector<std::byte>& out);
    std::size_t pending_output_size() const noexcept { return stream_.pending_output_size(); }
    std::optional<MonoTime> next_deadline() const;
    void on_timer(MonoTime now);
    /// See StreamConnection::set_liveness_probe.
    void set_liveness_probe(std::optional<std::chrono::milliseconds> timeout, MonoTime now) {
        stream_.set_liveness_probe(timeout, now);
    }
    std::optional<ServiceSessionEvent> poll_event();
    /// Every queued event at once, oldest first, into `batch` (its old events are destroyed first; see
    /// EventQueue::take_all), to handle in place. Events queued while handling them wait for the next call.
    void take_events(std::vector<ServiceSessionEvent>& batch);
    bool is_closed() const noexcept { return stream_.is_closed(); }
    /// Messages received and queued for sending so far (for the host's counters).
    std::uint64_t messages_in() const noexcept { return messages_in_; }
    std::uint64_t messages_out() const noexcept { return messages_out_; }

    // --- the session ---
    bool has_session() const noexcept { return service_ != nullptr; }
    std::uint32_t endpoint() const noexcept { return endpoint_; }
    std::uint32_t client_endpoint() const noexcept { return client_endpoint_; }
    const std::string& username() const noexcept { return username_; }
    const StreamConnection& stream() const noexcept { return stream_; }

    /// Answers a ServiceRequest: ServicePath, MemberName and RequestID must be the request's (the
    /// host's Responder sets them). A reply that cannot be sent (over the size limit) is replaced by
    /// an error reply with the same RequestID. Ignored without a session.
    void reply(MessageEntry&& entry, MonoTime now);
    /// Takes back a handled request's entry vector (the request entry is destroyed now) for the next
    /// message. Optional: a request not handed back is only freed.
    void recycle(ServiceRequest&& request) noexcept { stream_.entry_vectors().give(std::move(request.entries)); }
    /// Sends an entry the client did not ask for (EventReq, PipePacket, PipeClosed, WireClosed, …).
    /// Errors: InvalidState without a session or after close; BufferLimitViolation over the size limit.
    Result<void> send(MessageEntry entry, MonoTime now);
    /// Sends a WirePacket now, or holds it (replacing an older held packet of the same service path
    /// and member: wires keep only the newest value) while more than wire_hold_bytes of output wait.
    void send_wire_packet(MessageEntry entry, MonoTime now);
    /// send() and send_wire_packet() for an entry many sessions send unchanged (a wire value or event
    /// for every client of a member): its bytes, encoded once per message format, are copied after this
    /// session's message header. Errors: as send(); the entry's encoding error (EncodedEntry::bytes).
    Result<void> send(const EncodedEntry& entry, MonoTime now);
    void send_wire_packet(std::shared_ptr<const EncodedEntry> entry, MonoTime now);
    /// Sends a request to the client (CallbackCallReq); the RequestID is assigned here and returned.
    /// The answer arrives as ServiceCallbackResponse. Errors: as send().
    Result<std::uint32_t> request(MessageEntry entry, MonoTime now);
    /// Completes a ServiceObjectTypeQuery. Unknown tokens are ignored.
    void answer_object_type(std::uint64_t token, Result<ObjectTypeInfo> info, MonoTime now);
    /// Completes a ServiceAdmission: OK opens the session (the connect reply, then ServiceSessionOpened);
    /// an error is the connect's error reply (e.g. the device's AuthenticationError). Returns false when
    /// the token is unknown or the connection closed meanwhile: the service must then drop what it
    /// prepared for that endpoint.
    bool answer_admission(std::uint64_t token, Result<void> outcome, MonoTime now);
    /// Sends the DisconnectClientRet held for a ServiceSessionClosed's `disconnect_token`. Returns false
    /// (nothing sent) when the token is unknown or answered already, or the connection closed meanwhile.
    bool answer_disconnect(std::uint64_t token, MonoTime now);
    /// Ends the connection after the pending output (the host's close()).
    void close(RRError error);

private:
    using WireKey = std::pair<std::string, std::string>;
    struct PendingObjectType {
        MessageHeader header;
        MessageEntry reply;
    };

    void drain_stream(MonoTime now);
    void on_message(Message&& m, MonoTime now);
    void on_entries(Message& m, MonoTime now);
    /// Queues a ServiceRequest for `e`: in the received message's vector when `e` is its only entry.
    void queue_request(MessageEntry&& e, bool needs_reply);
    void handle_special(const MessageHeader& h, MessageEntry&& e, MonoTime now);
    void handle_session_entry(const MessageHeader& h, MessageEntry&& e, MonoTime now);
    void handle_session_op(MessageEntry&& e, MonoTime now);
    void connect_client(const MessageHeader& h, MessageEntry&& e, bool combined, MonoTime now);
    void get_service_desc(const MessageHeader& h, MessageEntry&& e, MonoTime now);
    void object_type_name(const MessageHeader& h, MessageEntry&& e, MonoTime now);
    /// `disconnect_token`: ServiceSessionClosed's (0: the reply of a DisconnectClient is not held).
    void close_session(std::uint64_t disconnect_token = 0);
    void open_session(const MessageHeader& h, MessageEntry reply, bool combined, bool return_defs,
                      std::shared_ptr<HostedService> service, std::uint32_t endpoint, std::string username,
                      bool authenticated, MonoTime now);
    void reply_special(const MessageHeader& request_header, MessageEntry reply, MonoTime now);
    Message session_message(MessageEntry&& entry);
    /// session_message's header, without entries (for an EncodedEntry).
    Message session_header(const MessageEntry& entry);
    void flush_held_wires(MonoTime now);
    /// What a held wire value is: a packet of this session, or one shared by many (EncodedEntry).
    using HeldWire = std::variant<MessageEntry, std::shared_ptr<const EncodedEntry>>;

    ServiceHost& host_;
    ServiceSessionConfig config_;
    StreamConnection stream_;
    EventQueue<ServiceSessionEvent> events_;
    std::vector<StreamEvent> stream_batch_;  // drain_stream's
    std::vector<MessageEntry>* lone_entry_ = nullptr;  // while on_message handles a message of one entry: its vector
    bool closed_reported_ = false;

    std::shared_ptr<HostedService> service_;
    std::uint32_t endpoint_ = 0;
    std::uint32_t client_endpoint_ = 0;
    std::string username_;
    bool authenticated_ = false;

    std::uint16_t message_id_ = 0;
    std::uint64_t messages_in_ = 0, messages_out_ = 0;
    std::uint32_t callback_request_counter_ = 0;
    std::map<std::uint32_t, MonoTime> pending_callbacks_;  // RequestID → deadline
    std::uint64_t object_type_counter_ = 0;
    std::map<std::uint64_t, PendingObjectType> pending_object_types_;
    std::map<WireKey, HeldWire> held_wires_;
    struct PendingAdmission {
        std::uint64_t token = 0;
        MessageHeader header;
        MessageEntry reply;
        bool combined = false, return_defs = true;
        std::shared_ptr<HostedService> service;
        std::uint32_t endpoint = 0;
        std::string username;
    };
    std::optional<PendingAdmission> admission_;  // at most one: a connection carries one session
    std::uint64_t admission_counter_ = 0;
    struct PendingDisconnect {
        std::uint64_t token = 0;
        MessageHeader header;
        MessageEntry reply;
    };
    std::optional<PendingDisconnect> disconnect_;  // a DisconnectClientRet waiting for answer_disconnect()
    std::uint64_t disconnect_counter_ = 0;
};

}  // namespace rr
