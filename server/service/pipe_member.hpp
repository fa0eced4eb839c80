// The service side of a pipe member (robdef `pipe T name`; wire.md §6.7 "pipe"): one PipeEndpoint per
// connected (client session, index). Entries: PipeConnectReq/Ret 1143/1144, PipeDisconnectReq/Ret
// 1145/1146, PipePacket 1141 (both ways), PipePacketRet 1142 (acks), PipeClosed 1147.
//
//   connect     the requested index is used unless this client already has an endpoint at or above it:
//               then the new endpoint gets one more than the client's highest index (CORE's rule, so an
//               index in use is never refused); −1 with no endpoint gives 1. The reply carries the index.
//               `[unreliable]` pipes grant `unreliable` when asked. on_connect runs before the reply (it
//               may refuse with an error, which becomes the reply).
//   packets     numbered per endpoint from 1 (uint32, wrapping to 0 after 2^32−1); client packets are
//               unpacked against the pipe type and passed to on_packet in arrival order (one stream
//               transport keeps them ordered); `requestack` is answered with PipePacketRet.
//               Packets from a client on a `[readonly]` pipe are ignored, as CORE does.
//   backlog     PipeEndpoint::send refuses (BufferLimitViolation, "pipe backlog full") while more than
//               max_backlog_bytes() are queued for that client; a packet is never dropped silently.
//   close       PipeEndpoint::close sends PipeClosed; a client PipeDisconnectReq, the end of the client's
//               session and the release of the object's path drop the endpoint too. on_close runs once
//               per endpoint in every case.
//
// Threads: every function is thread-safe; handlers run on the client's strand (on_close may also run
// on the thread that called close() or ObjectService::release_path), without any lock of this member.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "server/service/member_connections.hpp"
#include "server/service/service_object.hpp"

namespace rr::server {

class PipeMember;

/// One client's end of a pipe; session(), service_path() and is_open() are MemberConnection's.
class PipeEndpoint : public std::enable_shared_from_this<PipeEndpoint>, public detail::MemberConnection {
public:
    std::int32_t index() const noexcept { return index_; }
    bool unreliable() const noexcept { return unreliable_; }

    /// Sends one packet (packed once, checked against the pipe type) from any thread; returns its packet
    /// number. `request_ack` asks the client for a PipePacketRet (delivered to PipeMember::on_ack).
    /// Errors: InvalidOperation (endpoint closed), ReadOnlyMember (`[writeonly]` pipe: only clients
    /// send), the packing error, BufferLimitViolation (backlog full, or the session's send queue full),
    /// ConnectionError (client gone).
    Result<std::uint32_t> send(const Value& packet, bool request_ack = false);
    /// Closes from the service side: PipeClosed to the client, then on_close. Idempotent.
    void close();

private:
    friend class PipeMember;
    PipeEndpoint(std::weak_ptr<PipeMember> member, std::shared_ptr<const detail::MemberInfo> info, SessionRef session,
                 std::string path, std::int32_t index, bool unreliable);

    const std::weak_ptr<PipeMember> member_;
    const std::shared_ptr<const detail::MemberInfo> info_;
    const std::int32_t index_;
    const bool unreliable_;
    std::mutex send_mutex_;  // packet numbers are assigned and queued in one step
    std::atomic<std::thread::id> send_owner_{};
    std::uint32_t send_number_ = 0;
};

/// Endpoints by (session endpoint, pipe index). on_connect (runs before the PipeConnectRet; an error
/// refuses the connection and is the reply), on_close, drop_session and drop_path are
/// MemberConnections'.
class PipeMember : public std::enable_shared_from_this<PipeMember>,
                   public detail::MemberConnections<PipeEndpoint, std::pair<std::uint32_t, std::int32_t>> {
public:
    using PacketHandler = std::function<void(const std::shared_ptr<PipeEndpoint>& endpoint, Value packet)>;
    using AckHandler = std::function<void(const std::shared_ptr<PipeEndpoint>& endpoint, std::uint32_t packet_number)>;

    void on_packet(PacketHandler handler);
    void on_ack(AckHandler handler);

    const std::string& name() const noexcept;
    bool unreliable() const noexcept { return unreliable_; }
    /// Open endpoints (a snapshot).
    std::vector<std::shared_ptr<PipeEndpoint>> endpoints() const;
    /// Sends `packet` on every open endpoint; returns how many took it (errors per endpoint are skipped).
    std::size_t broadcast(const Value& packet);

    /// Bytes that may wait for one client before send() refuses. Default 1 MiB.
    void set_max_backlog_bytes(std::size_t bytes) noexcept { max_backlog_.store(bytes); }
    std::size_t max_backlog_bytes() const noexcept { return max_backlog_.load(); }

    // --- used by ServiceObject (on the client's strand) ---
    PipeMember(std::shared_ptr<const detail::MemberInfo> info, bool unreliable);
    void handle_request(const SessionRef& session, MessageEntry&& entry, Responder responder);
    void handle_packet(const SessionRef& session, MessageEntry&& entry);
    void clear_handlers();

private:
    friend class PipeEndpoint;
    using Key = std::pair<std::uint32_t, std::int32_t>;  // session endpoint, pipe index
    /// PipeEndpoint::close: removed, with PipeClosed to the client.
    void close_endpoint(const std::shared_ptr<PipeEndpoint>& endpoint);

    const std::shared_ptr<const detail::MemberInfo> info_;
    const bool unreliable_;
    std::atomic<std::size_t> max_backlog_{1024 * 1024};
    std::shared_ptr<const PacketHandler> on_packet_;  // guarded by mutex_
    std::shared_ptr<const AckHandler> on_ack_;        // guarded by mutex_
};

}  // namespace rr::server
