// Rate groups (issue 56): the JSON sockets' subscriptions of one wire with the same max_rate_hz share
// one upstream subscription and one pending value. The device's value is offered once to the group
// (one lock, one swap), not to every subscription; at each window of the rate (the grid of
// rate_window.hpp) the group hands its newest value to its members, from one timer per group, with no
// registration per member and window. A member is told each handed value through the handler it gave
// when it joined (made once per subscription), and the WireClosed of the wire (the group is gone then).
//
// Semantics kept from a subscription's own RateWindow: the newest value at most once per window
// (the first one of an open window at once, later ones replaced until the next window's start), the
// last value always handed out (a value waiting arms the group's timer); a member joining a group
// whose wire is connected gets the newest value at once. What a member does with a value (its socket's
// backpressure, coalescing while it is behind) is its own affair: a slow socket never holds up the group.
// Order: values are handed out outside the group's locks, from the device's strand (a value in an open
// window), the group's timer (a window's start) and join() (the newest, to the member joining), so one
// member can be handed an older value after a newer one (a member joining while a value arrives: the
// value's own hand-out may reach it before join() hands it the one before). Each value carries its
// place in the group's order (`seq`), and a member keeps only values newer than the newest it kept.
// Thread-safe: values arrive on the device's strand, the timers run on `executor`, members join and
// leave from their sockets.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <tuple>

#include <boost/asio/any_io_executor.hpp>

#include "base/error/rr_error.hpp"
#include "server/gateway/rate_window.hpp"
#include "server/gateway/shared_entry.hpp"

namespace rr::server::gateway {

class WireRateGroups : public std::enable_shared_from_this<WireRateGroups> {
public:
    using OnEntry = std::function<void(const SharedEntryPtr&)>;
    using Done = std::function<void(Result<void>)>;
    /// A member's handler: a value handed to it, with the number of values the group replaced unseen
    /// since its previous hand-out (the same for every member; 0 with the WireClosed), and `seq`, the
    /// value's place in the group's order (its first value 1, each later one more; the WireClosed after
    /// them all). A member may be handed an older value after a newer one (see Order above): it keeps a
    /// value only when its `seq` is above that of every value it kept before.
    using OnValue = std::function<void(const SharedEntryPtr&, std::uint64_t coalesced, std::uint64_t seq)>;

    /// Where a group's values come from: the wire `member` at `path` of `source` (a DeviceMirror; only
    /// its address is the key), subscribed once per group (DeviceMirror::subscribe's contract: `done`
    /// once the wire holds, maybe before `subscribe` returns; the WireClosed ends it) and unsubscribed
    /// when the group's last member leaves.
    struct Upstream {
        const void* source = nullptr;
        std::string path, member;
        std::function<std::uint64_t(OnEntry on_entry, Done done)> subscribe;
        std::function<void(std::uint64_t)> unsubscribe;
    };

    static std::shared_ptr<WireRateGroups> create(boost::asio::any_io_executor executor) {
        return std::shared_ptr<WireRateGroups>(new WireRateGroups(std::move(executor)));
    }
    ~WireRateGroups();

    /// Joins the group of `upstream`'s wire at `period` (made, and subscribed upstream, by its first
    /// member). `done` is called once: at once when the group's wire holds (after `on_value` got the
    /// newest value, if any), else when it does or fails (the member is gone then). Returns the member's
    /// id for leave(). Call without holding locks `on_value` or `done` take.
    std::uint64_t join(Upstream upstream, RateClock period, OnValue on_value, Done done);
    /// The member leaves (unknown ids ignored); the last one's leaving unsubscribes the group upstream.
    /// A hand-out already under way may still call its `on_value` once (the members' list it walks is
    /// a snapshot): the handler must ignore a value for a subscription that has ended.
    void leave(std::uint64_t member);

    /// Groups now (for tests and diagnostics).
    std::size_t groups() const;
    /// Device values offered to groups so far (one per value and group, whatever its members).
    std::uint64_t offers() const noexcept;
    /// Values handed to members so far (one per window and member at most).
    std::uint64_t handed() const noexcept;
    /// Values replaced in a group before they were handed out.
    std::uint64_t coalesced() const noexcept;

private:
    struct Group;
    using Key = std::tuple<const void*, std::string, std::string, std::int64_t>;
    explicit WireRateGroups(boost::asio::any_io_executor executor) : executor_(std::move(executor)) {}
    void offer(const std::shared_ptr<Group>& g, const SharedEntryPtr& e);
    void arm(const std::shared_ptr<Group>& g);  // under g's mutex
    void on_window(const std::shared_ptr<Group>& g);
    void subscribed(const std::shared_ptr<Group>& g, Result<void> r);
    void forget(const std::shared_ptr<Group>& g);

    boost::asio::any_io_executor executor_;
    mutable std::mutex mutex_;  // groups_, members_ (taken before a group's mutex, never after)
    std::map<Key, std::shared_ptr<Group>> groups_;
    std::map<std::uint64_t, std::shared_ptr<Group>> members_;
    std::uint64_t next_member_ = 1;
    std::atomic<std::uint64_t> offers_{0}, handed_{0}, coalesced_{0};
};

}  // namespace rr::server::gateway
