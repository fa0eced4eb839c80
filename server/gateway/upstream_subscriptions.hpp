// The fan-out tables of one device: its wires and events as the gateway's subscribers share them, for
// both front ends (native clients' sessions and the JSON API's internal subscribers). Per wire member
// the gateway holds one wire connection upstream, whatever the number of subscribers; this records who
// gets each wire's values and each event, the state of that upstream connection, the requests waiting
// for it, and the newest value for late subscribers.
//
// Bookkeeping only: no I/O. The owner (MirrorService) sends the WireConnectReq / WireDisconnectReq
// the results ask for and delivers values to the targets returned, outside the lock. Thread-safe.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "base/error/rr_error.hpp"
#include "server/gateway/shared_entry.hpp"
#include "server/node/service.hpp"

namespace rr::server::gateway {

class UpstreamSubscriptions {
public:
    /// Service path (gateway naming) and member name.
    using MemberKey = std::pair<std::string, std::string>;
    /// Called once with the outcome of the upstream wire connect a subscription waited for.
    using Ready = std::function<void(Result<void>)>;
    /// An internal subscriber's handler: WirePackets and, when the device closes the wire, WireClosed;
    /// or the events of its member.
    using OnEntry = std::function<void(const SharedEntryPtr&)>;
    struct InternalSub {
        std::uint64_t id;
        OnEntry on_entry;
    };
    /// Copied on write: a value fanned out takes a reference to the list, not a copy of every handler.
    using InternalSubs = std::shared_ptr<const std::vector<InternalSub>>;

    /// A wire's native subscribers, copied on write like InternalSubs (never null in Targets).
    using SessionList = std::shared_ptr<const std::vector<SessionRef>>;
    /// Who a value goes to.
    struct Targets {
        SessionList sessions;
        InternalSubs internal;
    };
    /// What a subscriber found when joining a wire.
    struct Joined {
        /// The upstream wire is connected: the subscription holds now (its Ready was not kept).
        bool ready = false;
        /// The wire's newest value (null when none has arrived yet), for the subscriber at once. An
        /// internal subscriber gets it also while the upstream connect is in flight: a device sends a
        /// wire's value before its WireConnectRet, so a subscriber joining between the two would otherwise
        /// wait for the next change.
        SharedEntryPtr last;
    };

    /// A native client's WireConnectReq: `session` joins the wire `key` (once, however often it asks).
    /// Not ready: `on_ready` is kept until the upstream connect completes; call begin_connect(key). Such
    /// a session is sent newest(key) after its WireConnectRet (values may come before it).
    Joined join_wire(const MemberKey& key, const SessionRef& session, Ready on_ready);
    /// A native client's WireDisconnectReq. True when it was the wire's last subscriber and the wire is
    /// connected upstream: the caller disconnects it there (the wire is forgotten here).
    bool leave_wire(const MemberKey& key, const SessionRef& session);
    /// Whether `session` joined the wire `key` (its WirePackets, the wire's OutValue, may pass upstream).
    bool has_session(const MemberKey& key, const SessionRef& session) const;
    /// A closed session leaves every wire: the wires it was the last subscriber of, connected
    /// upstream, for the caller to disconnect there.
    std::vector<MemberKey> leave_all(std::uint32_t endpoint);

    /// A gateway-internal subscriber (JSON API) of a wire (`is_wire`) or of an event; its id for
    /// remove_internal(). An event subscription is always ready. For a wire, as join_wire.
    std::pair<std::uint64_t, Joined> add_internal(const MemberKey& key, bool is_wire, OnEntry on_entry, Ready on_ready);
    /// Removes the internal subscriber `id` everywhere: the wires it was the last subscriber of,
    /// connected upstream, for the caller to disconnect there.
    std::vector<MemberKey> remove_internal(std::uint64_t id);

    /// True when a WireConnectReq for `key` must be sent now: the wire has subscribers and is neither
    /// connected nor being connected upstream (it is being connected from now on).
    bool begin_connect(const MemberKey& key);
    /// The outcome of that WireConnectReq: the subscriptions waiting for it, to call with `outcome`
    /// outside any lock. On failure the wire's sessions are dropped (nobody holds a wire connection that
    /// does not exist upstream); internal subscribers stay, to be connected when the device is back.
    std::vector<Ready> connect_done(const MemberKey& key, const Result<void>& outcome);
    /// No device connection to connect `key` on: its waiting subscriptions, to fail.
    std::vector<Ready> no_upstream(const MemberKey& key);
    /// The device connection was lost: no wire is connected upstream any more; every waiting
    /// subscription, to fail. The subscribers stay.
    std::vector<Ready> upstream_lost();
    /// The device connection is back: the wires that still have subscribers, to connect again
    /// (begin_connect each).
    std::vector<MemberKey> upstream_back();

    /// A WirePacket from the device (service path in gateway naming): kept as the wire's newest value;
    /// who gets it (nullopt when the wire has no subscription here).
    std::optional<Targets> wire_value(const SharedEntryPtr& value);
    /// WireClosed from the device: the wire and its subscriptions are gone; who gets the WireClosed.
    std::optional<Targets> wire_closed(const MemberKey& key);
    /// The internal subscribers of the event `key` (null when none).
    InternalSubs event_subscribers(const MemberKey& key) const;

    /// The newest value of the wire `key` (null when none has arrived or the wire has no subscription).
    SharedEntryPtr newest(const MemberKey& key) const;

    /// Wires with a subscription here (for tests and status).
    std::size_t wire_count() const;

private:
    struct Wire {
        SessionList sessions = empty_sessions();
        InternalSubs internal;
        bool upstream_connected = false;
        bool connecting = false;
        std::vector<Ready> waiting;  // subscriptions waiting for the upstream connect
        SharedEntryPtr last;         // newest value, for late subscribers
    };
    static bool unused(const Wire& w);
    static const SessionList& empty_sessions();

    mutable std::mutex mutex_;
    std::map<MemberKey, Wire> wires_;
    std::map<MemberKey, InternalSubs> events_;
    std::uint64_t next_id_ = 1;
};

}  // namespace rr::server::gateway
