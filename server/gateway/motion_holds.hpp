// Who holds a device's motion, and until when (docs/security.md "Motion safety"): one holder at a time.
// Pure bookkeeping: time comes in as arguments; MotionGuard (motion_guard.hpp) owns an instance per
// device, under its mutex, and acts on what it returns (stops, timers, liveness probes).
//
// A holder is one client of the gateway (an RR session, a JSON WebSocket, a user's HTTP requests from
// one address) and holds while any of these lasts:
//   * a hold-to-run call's (clamped) timeout, renewed by each call;
//   * a motion without a timeout of its own (a token: a call waiting for its end, a call with wait
//     false, a generator), until it ends, something stops the device, or its owner goes away;
//   * a command stream, while its packets keep coming (silent for the bound: it has ended).
// Another client's motion request meanwhile is refused with a message naming the holder.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "base/error/rr_error.hpp"

namespace rr::server::gateway {

/// A client that may start motion, as the refusal names it and the guard reaches it.
struct MotionClient {
    /// Who holds: two requests with one key are one holder (an RR session: its endpoint; a JSON
    /// WebSocket: the socket; HTTP: the user and address, so that a script's successive requests renew
    /// one hold).
    std::string key;
    /// Whose going away ends the motions it starts (an HTTP request's connection); "" = `key`.
    std::string owner;
    std::string user;         ///< gateway or device user; "" when anonymous
    std::string description;  ///< "JSON WebSocket from 10.0.0.5", "rr+tcp session from 10.0.0.5:40112"
    /// auth: passthrough: the client's own upstream session, where the gateway sends its stops first
    /// (0: the gateway's shared session only).
    std::uint32_t device_session = 0;
    /// Turns a short liveness probe of the client's connection on (the bound) or off (nullopt): on while
    /// it holds a motion without a timeout of its own or a stream. Empty: the connection cannot be probed.
    std::function<void(std::optional<std::chrono::milliseconds>)> liveness;

    const std::string& owner_key() const noexcept { return owner.empty() ? key : owner; }
    /// "alice (JSON WebSocket from 10.0.0.5)", or the description alone without a user.
    std::string who() const;
};

class MotionHolds {
public:
    using Time = std::chrono::steady_clock::time_point;

    /// `silence`: how long a command stream may go without a packet before it counts as ended.
    explicit MotionHolds(std::chrono::milliseconds silence) : silence_(silence) {}

    /// Makes `client` the holder unless another holds at `now`; `since` (wall-clock text) is shown in
    /// refusals. Errors: ObjectLockedError "motion of <device> is held by <who> since <since>; …".
    Result<void> take(const MotionClient& client, Time now, const std::string& since, std::string_view device);
    /// The holder's hold-to-run call runs until `until` (after take()); returns what it ran until before.
    std::optional<Time> timed(Time until);
    /// A hold-to-run call of `key` did not run (refused by a lock or by the device): its hold is what it
    /// was before (`before`, timed() returned it), and an idle holder is released.
    void undo_timed(const std::string& key, std::optional<Time> before, Time now);
    /// A motion without a timeout of its own began (after take()); its token.
    std::uint64_t begin_untimed(const std::string& owner, std::string member);
    /// The motion ended (a waiting call answered, a generator finished). Unknown tokens are ignored.
    void end_untimed(std::uint64_t token);
    bool has_token(std::uint64_t token) const;
    /// A packet of the holder's command stream `member` (after take()).
    void stream_packet(const std::string& member, Time now);

    /// Something stopped the device: the hold ends, its tokens with it.
    void stopped();

    /// What the guard must do when a client goes away.
    struct Gone {
        bool stop = false;                  ///< the device must be stopped
        std::vector<std::uint64_t> tokens;  ///< motions it owned (ended now)
    };
    /// `owner` (a MotionClient::owner_key()) went away: its motions without a timeout end (a stop is
    /// needed when it owned any, or when it was the holder with a stream expire() has not reported silent);
    /// a hold-to-run hold of
    /// the holder's own ends with it too (its device timeout ends the motion).
    Gone gone(const std::string& owner, Time now);

    /// Streams silent for the bound at `now` end (returned: the device must be stopped when not empty);
    /// an idle hold is released.
    std::vector<std::string> expire(Time now);
    std::optional<Time> next_deadline() const;

    /// The holder, when one holds at `now`.
    const MotionClient* holder(Time now) const;
    /// When the holder took the hold (the text take() was given); "" without one.
    const std::string& since() const noexcept;
    /// Whether the holder needs its connection probed (an untimed motion or a stream), and who it is.
    const MotionClient* probed() const;

private:
    struct Holder {
        MotionClient client;
        std::string since;
        std::optional<Time> timed_until;
        std::map<std::uint64_t, std::string> untimed;  // token → owner
        std::map<std::string, Time> streams;           // member → last packet
    };
    bool active(const Holder& h, Time now) const;

    std::chrono::milliseconds silence_;
    std::optional<Holder> holder_;
    std::uint64_t next_token_ = 1;
};

}  // namespace rr::server::gateway
