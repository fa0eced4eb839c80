// Object locks and monitor locks of one service (wire.md §12; CORE ServerContext::ClientLockOp,
// check_lock, check_monitor_lock, RemoveClient and Service_lock.cpp), as plain bookkeeping: no
// threads, no clock (time is passed in), not thread-safe (ObjectService calls it under its mutex).
//
// Object locks (RequestObjectLock / RequestClientObjectLock / ReleaseObjectLock):
//   - a lock taken on service path P covers P and every object below it (`P.member`, `P.member[i]`,
//     at any depth), including objects resolved after the lock was taken;
//   - a user lock (endpoint 0) lets every session of its user through; a client lock (the session's
//     endpoint) lets only that session through, so other sessions of the same user are refused too;
//   - a lock cannot be taken when P is already covered by a lock or an object below P is locked
//     (even by the same user): ObjectLockedError "Object already locked";
//   - release: nothing locked at P answers OK; a lock taken on an ancestor of P cannot be released at
//     P ("Cannot release inherited lock"); another user's lock needs the `objectlockoverride`
//     privilege ("Service locked by user <name>");
//   - when a session closes, its client locks go, and its user's user locks go when it was that
//     user's last session.
// Path prefixes are compared at segment boundaries: a lock on `svc.child` does not cover
// `svc.child_by_int[1]` (CORE compares raw string prefixes there).
//
// Monitor locks (MonitorEnter / MonitorContinueEnter / MonitorExit), per object (exact path, not
// inherited): one session holds an object's monitor; requests from other sessions to that object get
// InvalidOperation "Object is currently monitor locked. Use MonitorEnter to obtain monitor lock";
// sessions that ask meanwhile wait in line (first come, first served). A holder that sends nothing
// to the object for kMonitorIdle loses the monitor (CORE: 30 s without a refresh). A waiter whose
// own timeout (ms, -1 = none) passes is dropped with RequestTimeout.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "base/error/rr_error.hpp"

namespace rr::server {

class ObjectLocks {
public:
    using Clock = std::chrono::steady_clock;
    static constexpr std::chrono::seconds kMonitorIdle{30};

    struct Holder {
        std::string path;         ///< the service path the lock was taken on
        std::string username;
        std::uint32_t endpoint;   ///< 0 for a user lock, else the session's endpoint (client lock)
    };

    /// True when `path` is `ancestor` or an object below it (`ancestor.` / `ancestor[` follows).
    static bool covers(std::string_view ancestor, std::string_view path) noexcept;

    // --- object locks ---
    /// Errors: ObjectLockedError "Object already locked".
    Result<void> lock(const std::string& path, const std::string& username, std::uint32_t endpoint);
    /// Errors: ObjectLockedError (inherited lock; another user's or session's lock without `override_`).
    Result<void> release(const std::string& path, const std::string& username, std::uint32_t endpoint, bool override_);
    /// The lock covering `path`, if any.
    std::optional<Holder> holder(std::string_view path) const;
    /// Whether a request from (`username`, `endpoint`) to `path` may pass the object locks.
    /// Errors: ObjectLockedError "Object locked by <name>".
    Result<void> check(std::string_view path, std::string_view username, std::uint32_t endpoint) const;
    /// Drops what a closing session held: its client locks, and its user's user locks when
    /// `last_session_of_user`.
    void session_closed(std::uint32_t endpoint, std::string_view username, bool last_session_of_user);
    std::size_t lock_count() const noexcept { return locks_.size(); }
    /// Every object lock held, by path.
    std::vector<Holder> locks() const;

    // --- monitor locks ---
    /// A monitor handed to a waiting session (answer its pending MonitorEnter/ContinueEnter "OK"), or
    /// a waiter that timed out (answer RequestTimeout).
    struct MonitorEvent {
        std::string path;
        std::uint32_t endpoint;
        bool granted;  ///< false: timed out
    };
    /// True when acquired at once; false when `endpoint` now waits in line. `timeout_ms` < 0: no limit.
    /// Errors: InvalidOperation "Already acquiring or acquired monitor lock".
    Result<bool> monitor_enter(const std::string& path, std::uint32_t endpoint, std::int32_t timeout_ms, Clock::time_point now,
                               std::vector<MonitorEvent>& events);
    /// True when `endpoint` holds the monitor (now); false while it still waits.
    /// Errors: InvalidOperation "Not acquiring monitor lock"; RequestTimeout when its wait timed out.
    Result<bool> monitor_continue(const std::string& path, std::uint32_t endpoint, Clock::time_point now,
                                  std::vector<MonitorEvent>& events);
    /// Leaves the monitor or the line. Nothing held at `path` answers OK.
    /// Errors: InvalidOperation "Not monitor locked" when another session holds it and `endpoint` is not waiting.
    Result<void> monitor_exit(const std::string& path, std::uint32_t endpoint, Clock::time_point now,
                              std::vector<MonitorEvent>& events);
    /// For a member request: passes (refreshing the holder's idle timer) unless another session holds
    /// the monitor. Errors: InvalidOperation.
    Result<void> monitor_check(const std::string& path, std::uint32_t endpoint, Clock::time_point now,
                               std::vector<MonitorEvent>& events);
    /// Expires idle holders and timed-out waiters.
    void monitor_poll(Clock::time_point now, std::vector<MonitorEvent>& events);
    /// Drops a closing session's monitors and waits.
    void monitor_session_closed(std::uint32_t endpoint, Clock::time_point now, std::vector<MonitorEvent>& events);
    /// The session holding the monitor of `path` (0: none).
    std::uint32_t monitor_holder(const std::string& path) const;
    /// When `endpoint`'s wait for the monitor of `path` times out (nullopt: it does not wait, or
    /// waits without a timeout).
    std::optional<Clock::time_point> monitor_wait_deadline(const std::string& path, std::uint32_t endpoint) const;
    /// Every monitor held at `now` (path, holding session), by path; holders idle for kMonitorIdle
    /// are left out (they lose the monitor at its next use).
    std::vector<std::pair<std::string, std::uint32_t>> monitor_holders(Clock::time_point now) const;
    /// Nothing is locked or monitored, and nobody waits.
    bool empty() const noexcept { return locks_.empty() && monitors_.empty(); }

private:
    struct Waiter {
        std::uint32_t endpoint;
        std::optional<Clock::time_point> deadline;
    };
    struct Monitor {
        std::uint32_t holder = 0;
        Clock::time_point last_use{};
        std::deque<Waiter> waiters;
    };
    /// Expires and hands over the monitor of one path; erases it when unused.
    void settle(std::map<std::string, Monitor>::iterator it, Clock::time_point now, std::vector<MonitorEvent>& events);

    std::map<std::string, Holder> locks_;  // by locked path
    std::map<std::string, Monitor> monitors_;
};

}  // namespace rr::server
