// A service registered on a node, as the node's connections see it: what is needed to answer the
// special requests (HostedService, core/session/service_host.hpp; wire.md §6.4) and to dispatch member
// requests (wire.md §6.7), plus the handles it gets for its clients (SessionRef) and their requests
// (Responder).
//
// Two implementations: ObjectService (a tree of C++ ServiceObjects typed by robdef) and, in the
// gateway, a mirror that forwards entries to a device.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "base/error/rr_error.hpp"
#include "base/message/encoded_entry.hpp"
#include "base/message/message.hpp"
#include "core/session/service_host.hpp"

namespace boost::asio {
class io_context;
}

namespace rr::server {

class ServerSession;

/// A client session as seen by a service: identity plus thread-safe sending. Obtained in
/// Service::on_session_open and kept by services that push to the client (events, wires, pipes,
/// callbacks).
class SessionRef {
public:
    SessionRef() = default;
    explicit SessionRef(std::weak_ptr<ServerSession> s);
    /// From a session known to be alive (the connection's own, per request): no weak_ptr lock.
    explicit SessionRef(const std::shared_ptr<ServerSession>& s);

    /// This client's endpoint id (unique within the node while it lives).
    std::uint32_t endpoint() const noexcept { return endpoint_; }
    /// Authenticated user name, empty when none.
    std::string username() const;
    /// False once the client is gone.
    bool alive() const;

    /// Sends an entry the client did not ask for (EventReq, WirePacket, PipePacket, PipeClosed, …).
    /// Thread-safe. Called on this session's strand (from a request handler) the entry is queued at
    /// once, ahead of the handler's reply. Errors: ConnectionError when the client is gone; BufferLimitViolation when the
    /// client's send queue is full (the caller decides: drop for wires, back off for pipes).
    Result<void> send(MessageEntry entry) const;
    /// Like send(), but a queued, unsent wire packet for the same service path and member is replaced
    /// (wire.md §6.3: wires keep only the newest value).
    Result<void> send_wire_packet(MessageEntry entry) const;
    /// send() and send_wire_packet() for an entry many clients get unchanged (a wire value or event
    /// for every client of a member, non-null): its bytes are encoded once per message format
    /// (base/message/encoded_entry.hpp) and copied into each client's message. Same errors.
    Result<void> send(std::shared_ptr<const EncodedEntry> entry) const;
    Result<void> send_wire_packet(std::shared_ptr<const EncodedEntry> entry) const;
    /// Sends a request to the client (CallbackCallReq) and calls `done` with the reply entry or an
    /// error (RequestTimeout, ConnectionError). `done` runs on the session's strand.
    void request(MessageEntry entry, std::function<void(Result<MessageEntry>)> done) const;
    /// Bytes waiting to be written to this client (for backpressure decisions).
    std::size_t queued_bytes() const;
    /// Base URL of the transport this client came in on, as CORE's service index reports it
    /// (`rr+tcp://<local address>:<port>/`, wire.md §11.2); empty when the transport did not say.
    std::string local_url() const;
    /// The client's address ("ip:port"; behind a trusted proxy, the proxy's client), "" when unknown.
    std::string peer() const;
    /// Probes the client's connection (StreamConnection::set_liveness_probe): a ConnectionTest every
    /// `timeout` / 5, the connection closed when nothing arrives for `timeout`; nullopt: off. Thread-safe.
    void set_liveness_probe(std::optional<std::chrono::milliseconds> timeout) const;

    friend bool operator==(const SessionRef& a, const SessionRef& b) noexcept { return a.endpoint_ == b.endpoint_; }

private:
    std::weak_ptr<ServerSession> session_;
    std::uint32_t endpoint_ = 0;
};

/// Where the replies of one client session's requests go (ServerConnection's). Thread-safe.
class ReplySink {
public:
    virtual ~ReplySink() = default;
    /// Sends a complete reply entry (header fields set) to the client; from any thread.
    virtual void send_reply(MessageEntry&& reply) = 0;
};

/// Completes one request exactly once, from any thread.
class Responder {
public:
    Responder() = default;
    /// Keeps the request's header fields (not its elements: a large argument is not copied).
    Responder(std::shared_ptr<ReplySink> sink, const MessageEntry& request);
    Responder(Responder&&) noexcept = default;
    Responder& operator=(Responder&&) noexcept = default;
    ~Responder();  // an unanswered request is answered with InternalError

    /// Sends `reply`: ServicePath, MemberName and RequestID are set from the request, and EntryType to
    /// request + 1 unless the reply already has one (CORE answers MemoryWrite with MemoryReadRet).
    void respond(MessageEntry&& reply);
    /// Sends an error reply (wire.md §5.2).
    void fail(RRError error);
    bool done() const noexcept { return !sink_; }

private:
    std::shared_ptr<ReplySink> sink_;
    MessageEntryType request_type_ = MessageEntryType::Null;
    std::uint32_t request_id_ = 0;
    std::string service_path_, member_name_;
};

/// A service a node hosts: what the session protocol needs (HostedService: definitions, root type,
/// attributes, login) plus its objects' behaviour.
class Service : public HostedService {
public:
    /// Type of the object at `path` (the root or a path reached through objrefs), for ObjectTypeName.
    /// `done` may be called from any thread. Errors: ObjectNotFound.
    virtual void object_type(const SessionRef& session, const std::string& path,
                             std::function<void(Result<ObjectTypeInfo>)> done) = 0;

    /// Called by Node::register_service with the node's io_context (for the service's own timers,
    /// e.g. monitor lock waits); the node outlives its registrations' use of it.
    virtual void attach(boost::asio::io_context& io) {}

    /// For services whose admits_sessions() is true: decide whether a client may open a session (its
    /// `username` and `credentials` element as the client sent them; empty / nullopt when absent), on
    /// any thread, by calling `done` once: OK opens it (on_session_open follows with a SessionRef of
    /// this `endpoint`), an error is what the client's connect gets. abandon_admission(endpoint) follows
    /// an OK the client no longer wants (its connection closed meanwhile).
    virtual void admit_session(std::uint32_t endpoint, std::string username, std::optional<MessageElement> credentials,
                               std::function<void(Result<void>)> done) {
        done(fail(MessageErrorType::InvalidOperation, "service does not admit sessions"));
    }
    virtual void abandon_admission(std::uint32_t endpoint) {}

    virtual void on_session_open(const SessionRef& session) {}
    /// The client's session ended: DisconnectClient, or its connection closed.
    virtual void on_session_close(const SessionRef& session) {}
    /// For services whose admits_sessions() is true, instead of on_session_close when the client sent
    /// DisconnectClient: end the session and call `ended` once, from any thread, when the service's
    /// own side of it has ended (the gateway's passthrough mirror: the device answered its
    /// DisconnectClient). The client's DisconnectClientRet waits for it, as CORE answers DisconnectClient
    /// only after its RemoveClient: a client whose disconnect returned finds the session's locks gone.
    /// The default is on_session_close, then `ended`.
    virtual void end_session(const SessionRef& session, std::function<void()> ended) {
        on_session_close(session);
        ended();
    }

    /// A member request from a client (EntryType ≥ 1111, odd), or a client-sent packet that needs no
    /// answer (PipePacket, PipePacketRet, WirePacket: `responder` is then empty and must be ignored).
    /// Runs on the session's strand; long work must be moved elsewhere and answered via `responder`.
    virtual void handle_entry(const SessionRef& session, MessageEntry&& entry, Responder responder) = 0;
};

}  // namespace rr::server
