// The gateway as the dead-man for one device's motion (docs/security.md "Motion safety"), used by every
// path a request takes to the device: raw RR sessions (MirrorService, shared and passthrough), the JSON
// API's REST requests and JSON WebSockets. The paths tell the guard about each request before it goes
// (admit), its answer (on_reply), and the client going away (client_gone); the guard
//   * clamps a hold-to-run call's timeout to the bound (motion_rules.hpp),
//   * refuses a second client's motion while one holds the device's motion (motion_holds.hpp),
//   * lets stops through every lock (is_stop) and ends every hold on a stop,
//   * ends what a departed client started without a timeout of its own (its generators aborted, then
//     the device's stops: halt() and command_mode = halt on the standard robot), and a command stream
//     silent for the bound (the same stops),
//   * turns a short liveness probe of the holder's connection on while it holds such a motion, so a
//     connection that stops forwarding without closing counts as gone within the bound.
// Thread-safe: called from connection strands and the device's strand; its timer runs on `executor`.
#pragma once

#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include <boost/asio/any_io_executor.hpp>
#include <boost/asio/steady_timer.hpp>

#include "base/message/message.hpp"
#include "server/gateway/motion_holds.hpp"
#include "server/gateway/motion_rules.hpp"

namespace rr::server::gateway {

class MotionGuard : public std::enable_shared_from_this<MotionGuard> {
public:
    /// Sends a request to the device on passthrough session `session` (0: the gateway's shared
    /// session); paths in gateway naming. `done` gets the reply or the error.
    using DeviceRequest = std::function<void(MessageEntry entry, std::uint32_t session,
                                             std::function<void(Result<MessageEntry>)> done)>;

    MotionGuard(boost::asio::any_io_executor executor, std::string device, MotionSafety settings, DeviceRequest request);
    ~MotionGuard();

    /// The device (re)connected: its root type and definitions decide the rules (MotionRules::compile).
    void set_root(const ObjectTypeInfo& root, const DeviceTypes* types);
    std::shared_ptr<const MotionRules> rules() const;
    const MotionSafety& settings() const noexcept { return settings_; }
    /// Told (without locks held) what the guard did: a clamp, a refusal, a stop, a silent stream.
    void set_event_listener(std::function<void(const std::string&)> listener);

    /// What admit() decided, for on_reply().
    struct Ticket {
        enum class Kind : std::uint8_t { pass, stop, timed, untimed, generator, generator_next };
        Kind kind = Kind::pass;
        std::uint64_t token = 0;        ///< untimed, generator: the motion's token
        bool waits = false;             ///< untimed: the call returns when the motion is done
        std::int32_t generator = -1;    ///< generator_next: the generator's index
        bool closes = false;            ///< generator_next: the request closes or aborts it
        /// timed: the holder's hold before this call, restored when the call does not run
        std::optional<std::chrono::steady_clock::time_point> timed_before;
    };

    /// A request of `client` on its way to the device (FunctionCallReq, PropertySetReq, WirePacket,
    /// WireConnectReq, GeneratorNextReq; others pass). Only the root object at `path` == the device's
    /// name is guarded. A hold-to-run call's timeout is clamped in place. Errors: ObjectLockedError
    /// naming the holder (a motion, a stream packet, a command wire's connect while another client
    /// holds); InvalidArgument (a hold-to-run call without a numeric timeout). A WirePacket refused is
    /// to be dropped.
    Result<Ticket> admit(const MotionClient& client, MessageEntry& entry);
    /// Whether admit() has anything to decide about `entry` (a member of the kinds guarded, on the root
    /// object): the paths skip building a MotionClient for every other request.
    bool concerns(const MessageEntry& entry) const;
    /// The device's answer to an admitted request (its reply entry, or the error when none came).
    void on_reply(const MotionClient& client, const Ticket& ticket, const Result<MessageEntry>& reply);
    /// `entry` stops motion (a stop function's call, a stop property's value): it passes every lock held
    /// at the gateway, and the gateway sends it on whatever lock the device knows (docs/security.md).
    bool is_stop(const MessageEntry& entry) const;

    /// `owner` (MotionClient::owner_key()) went away: what it started without a timeout of its own is
    /// ended (generators aborted, the device's stops sent on its passthrough session first, then on the
    /// shared one). `done` (optional) runs once those were answered (at most 2 s), at once when nothing
    /// was needed.
    void client_gone(const std::string& owner, std::function<void()> done = {});

    /// `{"holder", "user", "since"}` of the current holder for status displays; nullopt when free.
    struct HolderInfo {
        std::string who, user, since;
    };
    std::optional<HolderInfo> holder() const;

    /// Stops sent by the guard itself (client gone, silent stream), for tests and /metrics.
    std::uint64_t stops_sent() const;

private:
    using Clock = std::chrono::steady_clock;
    /// A motion without a timeout of its own: whose it is, its generator index (-1: none, or not yet
    /// answered), and the passthrough session it runs on.
    struct Motion {
        std::string key;
        std::int32_t index = -1;
        std::string member;
        std::uint32_t session = 0;
    };
    /// Under mutex_: the probe follows the holder that needs one; the calls to make after unlocking.
    void update_probe(std::vector<std::function<void()>>& after);
    void arm_timer();
    void on_timer();
    /// Sends generator aborts and the stops; `done` once answered (or after 2 s).
    void stop_device(std::vector<Motion> aborts, std::uint32_t session, std::string why, std::function<void()> done);
    void emit(const std::string& message) const;
    static std::string wall_clock_text();

    const std::string device_;
    const MotionSafety settings_;
    const DeviceRequest request_;
    boost::asio::steady_timer timer_;

    mutable std::mutex mutex_;
    std::shared_ptr<const MotionRules> rules_;
    MotionHolds holds_;
    std::map<std::uint64_t, Motion> motions_;        // by token
    std::optional<MotionClient> probing_;            // whose connection is probed now
    std::optional<Clock::time_point> timer_at_;
    std::function<void(const std::string&)> listener_;
    std::uint64_t stops_sent_ = 0;
};

}  // namespace rr::server::gateway
