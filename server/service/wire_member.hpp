// The service side of a wire member (robdef `wire T name`; wire.md §6.7 "wire"): one WireConnection
// per connected client session. Entries: WireConnectReq/Ret 1163/1164, WireDisconnectReq/Ret
// 1165/1166, WirePacket 1161 (both ways; header and entry MetaData `unreliable\n`), WireClosed 1167,
// WirePeekInValueReq/Ret 1181/1182, WirePeekOutValueReq/Ret 1183/1184, WirePokeOutValueReq/Ret
// 1185/1186. Directions are the client's: a client "in" value is the service's out value.
//
//   out value   set_out_value() stores the value with a `packettime` from the wall clock (TimeSpec since
//               1970 UTC, strictly increasing per wire) and sends it to every connection, packed once;
//               per client only the newest unsent packet is kept (SessionRef::send_wire_packet), so a
//               slow client skips values instead of queueing them. A new connection gets the current out
//               value right away (before the WireConnectRet, as CORE's broadcaster does).
//   in value    client WirePackets are unpacked against the wire type; a packet whose time stamp is not
//               newer than the last one accepted on that connection is dropped (as CORE); accepted ones
//               update the connection's and the wire's in value and run on_value.
//   peek/poke   PeekInValue answers the out value, PeekOutValue the last in value (ValueNotSet when
//               none), PokeOutValue sets the in value (time stamp from the request) and runs on_value
//               with a null connection. Handlers may replace these three defaults.
//   direction   `[readonly]` (clients only read): client packets are ignored, PeekOutValue and
//               PokeOutValue answer ReadOnlyMember. `[writeonly]` (clients only write): PeekInValue
//               answers WriteOnlyMember and set_out_value fails with ReadOnlyMember.
//
// Threads: every function is thread-safe; handlers run on the client's strand without any lock of
// this member held (on_close may also run on the thread that called close() / release_path).
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "core/value/timespec.hpp"
#include "server/service/member_connections.hpp"
#include "server/service/service_object.hpp"

namespace rr::server {

class WireMember;

/// A value with its wire time stamp.
struct TimedValue {
    Value value;
    TimeSpec time;
};

/// The current wall-clock time as a TimeSpec (seconds and nanoseconds since 1970-01-01 UTC).
TimeSpec wall_clock_timespec();

/// One client's connection of a wire; session(), service_path() and is_open() are MemberConnection's.
class WireConnection : public std::enable_shared_from_this<WireConnection>, public detail::MemberConnection {
public:
    /// Last value accepted from this client, if any.
    std::optional<TimedValue> in_value() const;
    /// Sends `value` to this client only (time stamp from the wall clock). Errors: InvalidOperation
    /// (closed), ReadOnlyMember (`[writeonly]` wire), packing errors, ConnectionError.
    Result<void> set_out_value(const Value& value);
    /// Closes from the service side: WireClosed to the client, then on_close. Idempotent.
    void close();

private:
    friend class WireMember;
    WireConnection(std::weak_ptr<WireMember> member, SessionRef session, std::string path)
        : MemberConnection(std::move(session), std::move(path)), member_(std::move(member)) {}

    const std::weak_ptr<WireMember> member_;
    mutable std::mutex mutex_;
    std::optional<TimedValue> in_;
    // Time stamp of the newest packet queued to this client; guarded by the member's send_order_mutex_.
    std::optional<TimeSpec> last_sent_;
};

/// Connections by (session endpoint, service path). on_connect (runs before the WireConnectRet; an
/// error refuses the connection and is the reply), on_close, drop_session and drop_path are
/// MemberConnections'.
class WireMember : public std::enable_shared_from_this<WireMember>,
                   public detail::MemberConnections<WireConnection, std::pair<std::uint32_t, std::string>> {
public:
    /// `connection` is null for a PokeOutValue.
    using ValueHandler =
        std::function<void(const std::shared_ptr<WireConnection>& connection, const Value& value, TimeSpec time)>;
    using PeekHandler = std::function<Result<TimedValue>(const SessionRef& session)>;
    using PokeHandler = std::function<Result<void>(const SessionRef& session, Value value, TimeSpec time)>;

    void on_value(ValueHandler handler);
    void set_peek_in_handler(PeekHandler handler);
    void set_peek_out_handler(PeekHandler handler);
    void set_poke_handler(PokeHandler handler);

    const std::string& name() const noexcept;
    robdef::MemberDirection direction() const noexcept;

    /// Stores `value` as the out value and sends it to every connection (see above).
    /// Errors: ReadOnlyMember (`[writeonly]`), packing errors (nothing is stored then).
    Result<void> set_out_value(Value value);
    /// Errors: ValueNotSet.
    Result<TimedValue> out_value() const;
    /// Errors: ValueNotSet.
    Result<TimedValue> in_value() const;
    std::vector<std::shared_ptr<WireConnection>> connections() const;

    // --- used by ServiceObject (on the client's strand) ---
    WireMember(std::shared_ptr<const detail::MemberInfo> info);
    void handle_request(const SessionRef& session, MessageEntry&& entry, Responder responder);
    void handle_packet(const SessionRef& session, MessageEntry&& entry);
    void clear_handlers();

private:
    friend class WireConnection;
    using Key = std::pair<std::uint32_t, std::string>;  // session endpoint, service path
    Result<MessageEntry> pack_packet(const Value& value, TimeSpec time, MessageEntryType type) const;
    Result<void> send_to(WireConnection& connection, const Value& value);
    /// A new connection's first packet: the out value, unless something as new reached it already.
    void send_current(WireConnection& connection);
    TimeSpec next_time();
    /// WireConnection::close: removed, with WireClosed to the client.
    void close_connection(const std::shared_ptr<WireConnection>& connection);

    const std::shared_ptr<const detail::MemberInfo> info_;
    // Held from taking a time stamp until the packet is queued to every target, and while a new
    // connection gets the current value: clients drop a packet older than the last one they got
    // (wire.md §6.7), so no client may get an older stamp after a newer one.
    std::mutex send_order_mutex_;
    // Guarded by mutex_ (MemberConnections'):
    std::optional<TimedValue> out_;
    std::optional<TimedValue> in_;
    TimeSpec last_time_{};
    std::shared_ptr<const ValueHandler> on_value_;
    std::shared_ptr<const PeekHandler> peek_in_, peek_out_;
    std::shared_ptr<const PokeHandler> poke_;
};

}  // namespace rr::server
