// A JSON WebSocket's subscriptions (docs/json-api.md §WebSocket): their ids, their state from
// "subscribe" to "closed", and the push policy of each: the newest wire value waiting while the client
// is behind (older ones coalesced), event and pipe pushes dropped and counted while it is congested.
// A subscription with a maximum rate (rate_window.hpp) sends at most one value per window: a wire's
// newest waits for the next window, a pipe's packets wait in a queue of `queue_length` (oldest dropped,
// counted) and leave one per window.
// No sockets and no locks: JsonSocketSession (json_socket.cpp) calls it under its own mutex, which
// also keeps a subscription's reply ahead of its pushes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <string_view>
#include <variant>
#include <vector>

#include "server/gateway/json_api.hpp"
#include "server/gateway/rate_window.hpp"
#include "server/gateway/session_endpoints.hpp"
#include "server/gateway/shared_entry.hpp"

namespace rr::server::gateway {

enum class SubscriptionKind : std::uint8_t { wire, event, pipe };

/// "wire", "event" or "pipe": the `kind` of the subscribe reply and of pushes.
std::string_view kind_name(SubscriptionKind kind);

struct JsonSubscription {
    SubscriptionKind kind = SubscriptionKind::event;
    bool may_write = true;  ///< auth: gateway allows `write` on the member (set_out_value, send)
    bool binary = false;    ///< "binary": true: values with numeric arrays go as binary pushes
    std::shared_ptr<const MemberTarget> target;  ///< shared: every push takes it, copying no strings
    std::shared_ptr<SessionEndpoints> own;  ///< made on the socket's device_login session; null: the gateway's shared one
    std::uint64_t upstream_id = 0;  ///< DeviceMirror subscription id, internal pipe id, or `own`'s id
    bool upstream_known = false;    ///< upstream_id is set: ending the subscription must undo it
    bool rate_group = false;        ///< a rate-limited wire: upstream_id is its WireRateGroups member id
    bool active = false;            ///< subscribe answered: pushes may go
    bool failed = false;            ///< subscribe failed before upstream_id was known
    SharedEntryPtr pending_wire;    ///< the newest wire value not yet sent
    std::uint64_t wire_seq = 0;     ///< a rate group's member: the `seq` of the newest value it was offered
    std::uint64_t dropped = 0;      ///< pushes dropped since the last one sent
    RateWindow rate;                ///< "max_rate_hz": one value per window (unlimited by default)
    double max_rate_hz = 0;         ///< as the client asked (echoed in the reply)
    std::size_t queue_length = 1;   ///< a rate-limited pipe's waiting packets, at most
    std::size_t queue_bytes_limit = 4u << 20;  ///< and their payload bytes (one packet alone always waits)
    std::deque<MessageElement> pipe_queue;     ///< a rate-limited pipe's packets waiting for their window
    std::size_t queued_bytes = 0;              ///< pipe_queue's payload bytes
};

/// What one event or pipe push of a subscription needs.
struct PushTicket {
    std::shared_ptr<const MemberTarget> target;
    std::uint64_t dropped = 0;  ///< dropped before this one: the push's "dropped" field
    bool binary = false;
};

/// A rate-limited pipe's packet taken from its queue for sending.
struct PipeToSend {
    std::uint64_t subscription = 0;
    MessageElement packet;
    PushTicket ticket;
};

/// What happens to a wire value or pipe packet offered to a subscription.
struct Offered {
    bool send_now = false;   ///< it may go now (flush_wires / the ticket)
    RateClock wait{0};       ///< else, when rate-limited and waiting: the rate's period (wake at its next window)
};

/// A waiting wire value taken for sending.
struct WireToSend {
    std::uint64_t subscription = 0;
    SharedEntryPtr value;
    std::shared_ptr<const MemberTarget> target;
    bool binary = false;
};

class JsonSubscriptions {
public:
    /// At most `max_subscriptions` at once (JsonSocketOptions::max_subscriptions).
    explicit JsonSubscriptions(std::size_t max_subscriptions) : max_(max_subscriptions) {}

    /// Adds `s` under a new id (from 1, never reused on the socket). BufferLimitViolation (400) when
    /// max_subscriptions are open.
    std::variant<std::uint64_t, ApiError> add(JsonSubscription s);
    /// nullptr when `sid` is not open.
    JsonSubscription* find(std::uint64_t sid);
    void erase(std::uint64_t sid) { subs_.erase(sid); }
    /// Removes and returns an answered subscription (unsubscribe); nullopt when `sid` is not one.
    std::optional<JsonSubscription> take_active(std::uint64_t sid);
    /// The answered subscription `sid` when it is of `kind`. InvalidArgument (400) when there is none,
    /// or naming both kinds when it is of another.
    std::variant<const JsonSubscription*, ApiError> find_active(std::uint64_t sid, SubscriptionKind kind) const;
    /// Whether `sid` is open and answered.
    bool is_active(std::uint64_t sid) const;
    /// Removes every subscription made on `own` (a device login's session); returns the ids of those
    /// that were answered (they get a "closed" push).
    std::vector<std::uint64_t> remove_own(const std::shared_ptr<SessionEndpoints>& own);
    /// Empties the registry (the socket closes) and returns what it held.
    std::map<std::uint64_t, JsonSubscription> take_all();

    /// A slot for one event or pipe push of `sid`: nullopt when `sid` is not answered, or when the
    /// client is `congested` (the push is then counted as dropped, and the next one sent reports it).
    std::optional<PushTicket> take_push(std::uint64_t sid, bool congested);
    /// A push taken with take_push was dropped after all: its ticket's `dropped` goes back to `sid`,
    /// plus one for itself.
    void return_push(std::uint64_t sid, std::uint64_t ticket_dropped);
    /// A new wire value for `sid` replaces any still waiting (counted as coalesced). `send_now` when
    /// `sid` is answered and its rate window is open at `now`; `wait` is the period of a rate-limited
    /// subscription whose value waits for its next window; neither when it waits for the reply, or
    /// `sid` is not open.
    /// `coalesced`: values replaced before this one elsewhere (its rate group), counted here too.
    /// `seq`: a rate group's order of its values (wire_rate_groups.hpp), 0 for none: a value whose `seq`
    /// is not above that of one offered before is older than it and is dropped (counted as coalesced).
    Offered offer_wire(std::uint64_t sid, SharedEntryPtr value, RateClock now = {}, std::uint64_t coalesced = 0,
                       std::uint64_t seq = 0);
    /// Whether an answered subscription has a wire value that may go at `now`.
    bool wires_waiting(RateClock now = {}) const;
    /// Moves the wire values of answered subscriptions that may go at `now` into `out` (cleared first),
    /// in id order; their rate windows count them as sent.
    void take_wires(std::vector<WireToSend>& out, RateClock now = {});
    /// Appends the periods of rate-limited answered subscriptions with a wire value waiting for a later
    /// window than `now`'s.
    void rate_waiting(RateClock now, std::vector<RateClock>& out) const;

    /// A packet for rate-limited pipe subscription `sid` joins its queue (the oldest dropped and counted
    /// beyond queue_length or queue_bytes_limit). When the window is open at `now` and the client not
    /// `congested`, the oldest queued packet is taken into `out` with its ticket (`send_now`); else
    /// `wait` is the period to wake at. Neither when `sid` is not answered.
    Offered offer_pipe(std::uint64_t sid, MessageElement packet, bool congested, RateClock now,
                       std::optional<PipeToSend>& out);
    /// At a window's start: the oldest queued packet of each rate-limited pipe whose window is open at
    /// `now` (none while `congested`) into `out` (cleared first); `waiting` gets the periods of those
    /// with packets still queued.
    void take_pipe_packets(std::vector<PipeToSend>& out, bool congested, RateClock now, std::vector<RateClock>& waiting);

    std::size_t size() const noexcept { return subs_.size(); }
    /// Subscriptions with a wire value or pipe packets waiting.
    std::size_t pending_wires() const;
    /// Event and pipe pushes dropped so far.
    std::uint64_t push_drops() const noexcept { return push_drops_; }
    /// Wire values replaced by a newer one before they were sent.
    std::uint64_t wire_coalesced() const noexcept { return wire_coalesced_; }

private:
    std::map<std::uint64_t, JsonSubscription> subs_;
    std::size_t max_;
    std::uint64_t next_id_ = 1;
    std::uint64_t push_drops_ = 0, wire_coalesced_ = 0;
};

}  // namespace rr::server::gateway
