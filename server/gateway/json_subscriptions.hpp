// A JSON WebSocket's subscriptions (docs/json-api.md §WebSocket): their ids, their state from
// "subscribe" to "closed", and the push policy of each: the newest wire value waiting while the client
// is behind (older ones coalesced), event and pipe pushes dropped and counted while it is congested.
// No sockets and no locks: JsonSocketSession (json_socket.cpp) calls it under its own mutex, which
// also keeps a subscription's reply ahead of its pushes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string_view>
#include <variant>
#include <vector>

#include "server/gateway/json_api.hpp"
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
    bool active = false;            ///< subscribe answered: pushes may go
    bool failed = false;            ///< subscribe failed before upstream_id was known
    SharedEntryPtr pending_wire;    ///< the newest wire value not yet sent
    std::uint64_t dropped = 0;      ///< pushes dropped since the last one sent
};

/// What one event or pipe push of a subscription needs.
struct PushTicket {
    std::shared_ptr<const MemberTarget> target;
    std::uint64_t dropped = 0;  ///< dropped before this one: the push's "dropped" field
    bool binary = false;
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
    /// A new wire value for `sid` replaces any still waiting (counted as coalesced). True when `sid` is
    /// answered, so the value may be sent now; false when it waits for the reply, or `sid` is not open.
    bool offer_wire(std::uint64_t sid, SharedEntryPtr value);
    /// Whether an answered subscription has a wire value waiting.
    bool wires_waiting() const;
    /// Moves the waiting wire values of answered subscriptions into `out` (cleared first), in id order.
    void take_wires(std::vector<WireToSend>& out);

    std::size_t size() const noexcept { return subs_.size(); }
    /// Subscriptions with a wire value waiting.
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
