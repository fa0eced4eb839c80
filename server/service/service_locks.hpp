// The object and monitor locks of one service as its clients meet them (docs/security.md "Object
// locks", "Monitor locks"): ObjectLocks' bookkeeping behind a mutex, plus what a service does around
// it: the lock operations of a ClientSessionOpReq answered (a MonitorEnter that must wait is parked and
// answered "OK" when the monitor is handed over, "Continue" after kMonitorWait, or RequestTimeout),
// member requests checked, and a closing session's locks dropped.
//
// ObjectService keeps the locks of its own objects here; the gateway's MirrorService keeps the locks
// held at the gateway for an `auth: shared` device (its clients share one session to the device).
//
// Thread-safe. Responders and the change listener are called without the mutex held.
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "server/node/service.hpp"
#include "server/service/object_locks.hpp"

namespace boost::asio {
class io_context;
}

namespace rr::server {

/// Whether a request of `type` to a member with these robdef `modifiers` passes object locks (monitor
/// locks still apply): `[nolock]` members for every request, `[nolockread]` members for property and
/// memory reads (CORE: the generated skels' IsRequestNoLock).
bool passes_object_locks(const std::vector<std::string>& modifiers, MessageEntryType type) noexcept;

class ServiceLocks : public std::enable_shared_from_this<ServiceLocks> {
public:
    /// A waiting MonitorEnter / MonitorContinueEnter is answered "Continue" after this (CORE: 5 s).
    static constexpr std::chrono::seconds kMonitorWait{5};

    /// Who asks. `endpoint` 0 is a request without a client session of its own (the gateway's JSON
    /// API): it passes the user locks of its user only, no client lock and no monitor.
    struct Requester {
        std::uint32_t endpoint = 0;
        std::string username;  ///< "" when not logged in
    };
    /// The asking user's privileges (`objectlock`, `objectlockoverride` in the password file).
    struct Privileges {
        bool lock = false;
        bool override_ = false;
    };
    /// A lock or monitor held now (for listings).
    struct Held {
        std::string path;
        std::string username;     ///< "" for an anonymous session's monitor
        std::string kind;         ///< "user" (RequestObjectLock), "client" (RequestClientObjectLock), "monitor"
        std::uint32_t endpoint;   ///< the session that took it
    };

    /// Whether `op` (a ClientSessionOpReq member name) may be asked for at all: object lock operations
    /// need a logged-in user (PermissionDenied "User must be authenticated to lock object") with
    /// either privilege (ObjectLockedError "User does not have object locking privileges"); monitor
    /// operations need neither (CORE ServerContext::ClientLockOp).
    static Result<void> check_privileges(std::string_view op, std::string_view username, Privileges privileges);

    /// Timers for waiting monitor requests; without an io_context a MonitorEnter that must wait is
    /// answered "Continue" at once (the client asks again).
    void attach(boost::asio::io_context& io);
    /// Called (any thread, no mutex held) after a lock or monitor was taken, released or handed over.
    void set_on_change(std::function<void()> on_change);

    /// Answers the lock operation `entry` (ClientSessionOpReq; member name RequestObjectLock,
    /// RequestClientObjectLock, ReleaseObjectLock, MonitorEnter with int32 `timeout`,
    /// MonitorContinueEnter, MonitorExit) on `entry.service_path`, an object that exists, for a
    /// requester that passed check_privileges(). Others get InvalidOperation "Invalid command" (as CORE).
    void handle_op(const Requester& who, Privileges privileges, const MessageEntry& entry, Responder responder);
    /// A user lock taken by the service itself (no session: CORE's ServerContext::RequestObjectLock):
    /// held for `username` until release_user_lock() or until a session of that user that logged in
    /// closes as the user's last. Errors: ObjectLockedError "Object already locked".
    Result<void> lock_for_user(const std::string& path, const std::string& username);
    /// Releases a lock taken on exactly `path`, whoever holds it. Nothing held there: OK.
    /// Errors: ObjectLockedError "Cannot release inherited lock" (the lock covering `path` was taken on
    /// an ancestor).
    Result<void> release_user_lock(const std::string& path);
    /// A member request to the object at `path`: passes unless another session holds its monitor
    /// (InvalidOperation "Object is currently monitor locked. Use MonitorEnter to obtain monitor lock")
    /// or, unless `nolock`, a lock of another user or session covers it (ObjectLockedError "Object
    /// locked by <user>"). A monitor holder's request keeps its monitor from going idle.
    Result<void> check(const std::string& path, const Requester& who, bool nolock);
    /// False while no object lock or monitor is held anywhere in the service: check() then passes every
    /// request, and callers may skip building its Requester.
    bool any() const noexcept { return any_.load(std::memory_order_acquire); }
    /// A client session closed: its client locks, monitors and waits go, and its user's user locks when
    /// it was `last_session_of_user`.
    void session_closed(std::uint32_t endpoint, std::string_view username, bool last_session_of_user);

    /// The object lock covering `path`, if any.
    std::optional<ObjectLocks::Holder> holder(std::string_view path) const;
    /// Every object lock and held monitor, by kind then path.
    std::vector<Held> held() const;
    /// Forgets waiting monitor requests without answering them (their connections are going away).
    void shutdown();

private:
    struct Parked;
    /// Keeps a MonitorEnter / MonitorContinueEnter that must wait (answered "Continue" after `wait`).
    void park(const std::string& path, std::uint32_t endpoint, Responder responder, std::chrono::milliseconds wait);
    /// Answers parked requests for `events` (mutex_ not held).
    void deliver(std::vector<ObjectLocks::MonitorEvent>& events);
    void changed() const;
    void update_any();  // mutex_ held
    /// How long a MonitorEnter / MonitorContinueEnter of `endpoint` that must wait is parked: kMonitorWait,
    /// or less when its timeout comes first (mutex_ held).
    std::chrono::milliseconds wait_for_monitor(const std::string& path, std::uint32_t endpoint,
                                               std::chrono::steady_clock::time_point now) const;

    mutable std::mutex mutex_;
    ObjectLocks locks_;
    std::map<std::uint32_t, std::string> monitor_users_;  // sessions that entered a monitor → user
    std::map<std::pair<std::string, std::uint32_t>, std::shared_ptr<Parked>> parked_;  // (path, endpoint)
    boost::asio::io_context* io_ = nullptr;
    bool shut_down_ = false;
    std::function<void()> on_change_;
    // Nothing locked or monitored: member requests pass without taking the mutex.
    std::atomic<bool> any_{false};
};

}  // namespace rr::server
