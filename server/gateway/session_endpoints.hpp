// The gateway's own event subscriptions, wire connections and pipe endpoints on one upstream session
// to a device: the session a JSON API client opened with `device_login` (auth: passthrough;
// docs/json-api.md "device_login"), so what that client receives and sends goes through the device's
// own login, privileges and locks for its user instead of the gateway's shared session. A device's
// MirrorService keeps one more on that shared session for the JSON API's pipe endpoints
// (shared_endpoints()), beside the downstream clients' pipes.
//
// Service paths are in gateway naming (the device's name as service name) both ways; the session's
// owner (PassthroughSessions) translates them. One wire connection per (path, member) is made however
// many subscriptions share it (RR allows one per client session); it is disconnected with the last.
// Events need no request: the device sends them to every session (wire.md §6.7).
//
// Thread-safe: deliver() and lost() come from the upstream session's strand, the rest from any thread;
// handlers are called without locks held.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "base/error/rr_error.hpp"
#include "base/message/message.hpp"
#include "server/gateway/shared_entry.hpp"

namespace rr::server::gateway {

/// What a pipe endpoint of the gateway itself hears (JSON API pipe subscriptions). `on_packet` gets the
/// packet's `packet` element and its number (acknowledgements the sender asked for are sent already);
/// `on_ack` a packet number the device acknowledged; `on_closed` once, when the device closes the
/// endpoint (PipeClosed) or the session ends: not after the owner closed it.
struct GatewayPipeHandlers {
    std::function<void(const MessageElement& packet, std::uint32_t packet_number)> on_packet;
    std::function<void(std::uint32_t packet_number)> on_ack;
    std::function<void(const RRError& reason)> on_closed;
};

/// What an event or wire subscription hears. `on_entry`: each EventReq / WirePacket of the member (one
/// SharedEntry per value); `on_closed` once, when the device closes the wire (WireClosed) or the session
/// ends: not after unsubscribe().
struct SubscriptionHandlers {
    std::function<void(const SharedEntryPtr&)> on_entry;
    std::function<void(const RRError& reason)> on_closed;
};

class SessionEndpoints : public std::enable_shared_from_this<SessionEndpoints> {
public:
    /// The upstream session, in gateway naming. `request` answers with the device's reply (or its
    /// error); `send` sends an entry that has no reply (ConnectionError when the session is gone);
    /// `queued_bytes` is what waits to be written to the device.
    struct Upstream {
        std::function<void(MessageEntry, std::function<void(Result<MessageEntry>)>)> request;
        std::function<Result<void>(MessageEntry)> send;
        std::function<std::size_t()> queued_bytes;
    };

    explicit SessionEndpoints(Upstream upstream);

    /// Subscribes to event or wire `member` of the object at `path`. A wire's first subscription sends
    /// WireConnectReq. `done` gets an id for unsubscribe(), or the device's error (ConnectionError once
    /// the session ended).
    void subscribe(std::string path, std::string member, bool is_wire, SubscriptionHandlers handlers,
                   std::function<void(Result<std::uint64_t>)> done);
    /// Ends a subscription (a wire's last one sends WireDisconnectReq). Unknown ids are ignored.
    void unsubscribe(std::uint64_t id);
    /// Sends a WirePacket (the client's OutValue, the device's InValue) on the wire connection of
    /// `entry` (path, member). Errors: InvalidOperation when this session has no such wire connection,
    /// ConnectionError when the session is gone.
    Result<void> send_wire_packet(MessageEntry entry);

    /// Connects a pipe endpoint (PipeConnectReq, index −1: the device chooses). `done` gets an id for
    /// the calls below or the device's error.
    void open_pipe(std::string path, std::string member, bool unreliable, GatewayPipeHandlers handlers,
                   std::function<void(Result<std::uint64_t>)> done);
    /// Sends `packet` (packed for the pipe's type) on the endpoint; returns its packet number (1, 2, …).
    /// Errors: InvalidArgument (unknown or closed id), BufferLimitViolation (the device does not read:
    /// more than 8 MiB wait), ConnectionError.
    Result<std::uint32_t> send_pipe_packet(std::uint64_t id, MessageElement packet, bool request_ack);
    /// Disconnects the endpoint (PipeDisconnectReq); no handler is called afterwards.
    void close_pipe(std::uint64_t id);

    /// An entry the device sent on the session (gateway naming): EventReq, WirePacket, WireClosed,
    /// PipePacket, PipePacketRet, PipeClosed; others are ignored.
    void deliver(MessageEntry&& entry);
    /// PipePacket / PipePacketRet (gateway naming) on a session other endpoints share: takes out and
    /// delivers the elements of these endpoints (acknowledging packets that ask for it) and leaves the
    /// rest in `entry`. Returns true when nothing is left.
    bool take_pipe_elements(MessageEntry& entry);
    /// PipeClosed (gateway naming) for `index` of pipe `member` at `path`: true when it closed one of
    /// these endpoints (its `on_closed` called), false when the pipe is not one of them.
    bool pipe_closed(const std::string& path, const std::string& member, std::int32_t index);
    /// The session ended: every subscription's and endpoint's `on_closed` gets `reason`; later calls
    /// fail with `reason` until resume().
    void lost(const RRError& reason);
    /// A new session to the device took the lost one's place (a shared session reconnected): calls
    /// work again. Ids stay unique across sessions.
    void resume();
    /// The owner ends the session: forgets everything without calling handlers or sending anything.
    void forget();

    std::size_t subscription_count() const;
    /// Pipe endpoints connected now (their PipeConnectReq answered; not those still connecting).
    std::size_t open_pipe_count() const;

private:
    using MemberKey = std::pair<std::string, std::string>;  // service path, member
    struct Subscriber {
        std::uint64_t id;
        std::shared_ptr<const SubscriptionHandlers> handlers;
    };
    struct Wire {
        bool connected = false;
        std::vector<Subscriber> subscribers;
        std::vector<std::pair<std::uint64_t, std::function<void(Result<std::uint64_t>)>>> waiting;  // connect in flight
    };
    struct Pipe {
        std::string path, member;
        bool unreliable = false;
        bool connected = false;
        std::int32_t index = -1;
        std::uint32_t send_number = 0;
        std::shared_ptr<const GatewayPipeHandlers> handlers;
    };

    RRError gone() const;
    void wire_connected(const MemberKey& key, Result<MessageEntry> r);
    bool pipe_connected(std::uint64_t id, Result<MessageEntry> r);  // false: closed while connecting

    const Upstream upstream_;
    mutable std::mutex mutex_;
    std::optional<RRError> lost_;
    std::uint64_t next_id_ = 1;
    std::map<MemberKey, std::vector<Subscriber>> events_;
    std::map<MemberKey, Wire> wires_;
    std::map<std::uint64_t, Pipe> pipes_;
    std::map<std::tuple<std::string, std::string, std::int32_t>, std::uint64_t> pipes_by_index_;
};

}  // namespace rr::server::gateway
