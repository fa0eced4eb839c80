#include "server/service/service_locks.hpp"

#include <algorithm>

#include <boost/asio/io_context.hpp>
#include <boost/asio/steady_timer.hpp>

#include "core/session/elements.hpp"

namespace rr::server {

namespace {

void answer(Responder& responder, const char* text) {
    MessageEntry r;
    r.elements.push_back(make_string_element("return", text));
    responder.respond(std::move(r));
}

}  // namespace

bool passes_object_locks(const std::vector<std::string>& modifiers, MessageEntryType type) noexcept {
    const bool read = type == MessageEntryType::PropertyGetReq || type == MessageEntryType::MemoryRead ||
                      type == MessageEntryType::MemoryGetParam;
    for (const auto& m : modifiers)
        if (m == "nolock" || (m == "nolockread" && read)) return true;
    return false;
}

struct ServiceLocks::Parked {
    Responder responder;
    std::unique_ptr<boost::asio::steady_timer> timer;
};

Result<void> ServiceLocks::check_privileges(std::string_view op, std::string_view username, Privileges privileges) {
    if (op.rfind("Monitor", 0) == 0) return {};
    if (username.empty()) return fail(MessageErrorType::PermissionDenied, "User must be authenticated to lock object");
    if (!privileges.lock && !privileges.override_)
        return fail(MessageErrorType::ObjectLockedError, "User does not have object locking privileges");
    return {};
}

void ServiceLocks::attach(boost::asio::io_context& io) {
    std::lock_guard lock(mutex_);
    io_ = &io;
}

void ServiceLocks::set_on_change(std::function<void()> on_change) {
    std::lock_guard lock(mutex_);
    on_change_ = std::move(on_change);
}

void ServiceLocks::changed() const {
    std::function<void()> f;
    {
        std::lock_guard lock(mutex_);
        f = on_change_;
    }
    if (f) f();
}

std::chrono::milliseconds ServiceLocks::wait_for_monitor(const std::string& path, std::uint32_t endpoint,
                                                        std::chrono::steady_clock::time_point now) const {
    auto wait = std::chrono::duration_cast<std::chrono::milliseconds>(kMonitorWait);
    // Parked no longer than the waiter's own timeout, which then answers RequestTimeout on time (parked
    // for kMonitorWait each time, a 7 s timeout was answered at 10 s).
    if (auto deadline = locks_.monitor_wait_deadline(path, endpoint)) {
        const auto left = std::chrono::ceil<std::chrono::milliseconds>(*deadline - now) + std::chrono::milliseconds(1);
        wait = std::clamp(left, std::chrono::milliseconds(1), wait);
    }
    return wait;
}

void ServiceLocks::update_any() { any_.store(!locks_.empty(), std::memory_order_release); }

void ServiceLocks::handle_op(const Requester& who, Privileges privileges, const MessageEntry& entry, Responder responder) {
    const std::string& op = entry.member_name;
    const std::string& path = entry.service_path;
    const auto now = std::chrono::steady_clock::now();
    std::vector<ObjectLocks::MonitorEvent> events;
    if (op == "RequestObjectLock" || op == "RequestClientObjectLock" || op == "ReleaseObjectLock") {
        Result<void> r;
        {
            std::lock_guard lock(mutex_);
            if (op == "ReleaseObjectLock")
                r = locks_.release(path, who.username, who.endpoint, privileges.override_);
            else
                r = locks_.lock(path, who.username, op == "RequestClientObjectLock" ? who.endpoint : 0);
            update_any();
        }
        if (!r) {
            responder.fail(r.error());
            return;
        }
        answer(responder, "OK");
        changed();
        return;
    }
    if (op == "MonitorEnter") {
        const MessageElement* t = entry.find("timeout");
        std::int32_t timeout = -1;
        if (!t || !read_scalar(*t, timeout)) {
            responder.fail(make_error(MessageErrorType::InvalidArgument, "MonitorEnter needs an int32 \"timeout\""));
            return;
        }
        Result<bool> r = false;
        std::chrono::milliseconds wait{};
        {
            std::lock_guard lock(mutex_);
            r = locks_.monitor_enter(path, who.endpoint, timeout, now, events);
            if (r) monitor_users_[who.endpoint] = who.username;
            if (r && !*r) wait = wait_for_monitor(path, who.endpoint, now);
            update_any();
        }
        deliver(events);
        if (!r) {
            responder.fail(r.error());
        } else if (*r) {
            answer(responder, "OK");
            changed();
        } else {
            park(path, who.endpoint, std::move(responder), wait);
        }
        return;
    }
    if (op == "MonitorContinueEnter") {
        Result<bool> r = false;
        std::chrono::milliseconds wait{};
        {
            std::lock_guard lock(mutex_);
            r = locks_.monitor_continue(path, who.endpoint, now, events);
            if (r && !*r) wait = wait_for_monitor(path, who.endpoint, now);
            update_any();
        }
        deliver(events);
        if (!r)
            responder.fail(r.error());
        else if (*r)
            answer(responder, "OK");
        else
            park(path, who.endpoint, std::move(responder), wait);
        return;
    }
    if (op == "MonitorExit") {
        Result<void> r;
        {
            std::lock_guard lock(mutex_);
            r = locks_.monitor_exit(path, who.endpoint, now, events);
            update_any();
        }
        deliver(events);
        if (!r) {
            responder.fail(r.error());
            return;
        }
        answer(responder, "OK");
        changed();
        return;
    }
    // ReleaseClientObjectLock is a known command name that CORE's ClientLockOp answers this way.
    responder.fail(make_error(MessageErrorType::InvalidOperation, "Invalid command"));
}

Result<void> ServiceLocks::check(const std::string& path, const Requester& who, bool nolock) {
    if (!any_.load(std::memory_order_acquire)) return {};
    std::vector<ObjectLocks::MonitorEvent> events;
    Result<void> r;
    {
        std::lock_guard lock(mutex_);
        r = locks_.monitor_check(path, who.endpoint, std::chrono::steady_clock::now(), events);
        if (r && !nolock) r = locks_.check(path, who.username, who.endpoint);
        update_any();
    }
    deliver(events);
    return r;
}

Result<void> ServiceLocks::lock_for_user(const std::string& path, const std::string& username) {
    Result<void> r;
    {
        std::lock_guard lock(mutex_);
        r = locks_.lock(path, username, 0);
        update_any();
    }
    if (r) changed();
    return r;
}

Result<void> ServiceLocks::release_user_lock(const std::string& path) {
    Result<void> r;
    bool had = false;
    {
        std::lock_guard lock(mutex_);
        auto h = locks_.holder(path);
        had = h.has_value();
        if (h) r = locks_.release(path, h->username, h->endpoint, true);
        update_any();
    }
    if (r && had) changed();
    return r;
}

void ServiceLocks::session_closed(std::uint32_t endpoint, std::string_view username, bool last_session_of_user) {
    std::vector<ObjectLocks::MonitorEvent> events;
    std::vector<std::shared_ptr<Parked>> parked;  // destroyed outside the mutex
    bool had = false;
    {
        std::lock_guard lock(mutex_);
        const auto before = locks_.lock_count();
        locks_.session_closed(endpoint, username, last_session_of_user);
        const bool monitored = monitor_users_.erase(endpoint) != 0;
        had = locks_.lock_count() != before || monitored;
        locks_.monitor_session_closed(endpoint, std::chrono::steady_clock::now(), events);
        for (auto it = parked_.begin(); it != parked_.end();) {
            if (it->first.second == endpoint) {
                parked.push_back(std::move(it->second));
                it = parked_.erase(it);
            } else {
                ++it;
            }
        }
        update_any();
    }
    deliver(events);
    if (had) changed();
}

std::optional<ObjectLocks::Holder> ServiceLocks::holder(std::string_view path) const {
    std::lock_guard lock(mutex_);
    return locks_.holder(path);
}

std::vector<ServiceLocks::Held> ServiceLocks::held() const {
    std::vector<Held> out;
    std::lock_guard lock(mutex_);
    for (const auto& h : locks_.locks()) out.push_back(Held{h.path, h.username, h.endpoint == 0 ? "user" : "client", h.endpoint});
    for (const auto& [path, endpoint] : locks_.monitor_holders(std::chrono::steady_clock::now())) {
        auto u = monitor_users_.find(endpoint);
        out.push_back(Held{path, u == monitor_users_.end() ? std::string() : u->second, "monitor", endpoint});
    }
    return out;
}

void ServiceLocks::shutdown() {
    std::map<std::pair<std::string, std::uint32_t>, std::shared_ptr<Parked>> parked;
    std::lock_guard lock(mutex_);
    shut_down_ = true;
    parked.swap(parked_);
}

void ServiceLocks::park(const std::string& path, std::uint32_t endpoint, Responder responder, std::chrono::milliseconds wait) {
    auto parked = std::make_shared<Parked>();
    parked->responder = std::move(responder);
    std::weak_ptr<ServiceLocks> weak = weak_from_this();
    std::weak_ptr<Parked> weak_parked = parked;
    auto on_timeout = [weak, weak_parked, path, endpoint](const boost::system::error_code& ec) {
        if (ec) return;
        auto self = weak.lock();
        if (!self) return;
        std::vector<ObjectLocks::MonitorEvent> events;
        std::shared_ptr<Parked> mine;
        {
            std::lock_guard lock(self->mutex_);
            self->locks_.monitor_poll(std::chrono::steady_clock::now(), events);
            self->update_any();
        }
        self->deliver(events);  // may answer this request "OK" or RequestTimeout
        {
            std::lock_guard lock(self->mutex_);
            auto it = self->parked_.find({path, endpoint});
            if (it != self->parked_.end() && it->second == weak_parked.lock()) {
                mine = std::move(it->second);
                self->parked_.erase(it);
            }
        }
        if (mine && !mine->responder.done()) answer(mine->responder, "Continue");
    };
    std::shared_ptr<Parked> replaced;
    bool granted_meanwhile = false;
    {
        std::lock_guard lock(mutex_);
        // Handed over between monitor_enter/continue and now (its event found nothing parked).
        granted_meanwhile = locks_.monitor_holder(path) == endpoint;
        if (io_ && !shut_down_ && !granted_meanwhile) {
            parked->timer = std::make_unique<boost::asio::steady_timer>(*io_, wait);
            // Armed before it is published: once in parked_, another connection's thread may take it
            // and cancel the timer (a timer is not safe for two threads at once).
            parked->timer->async_wait(std::move(on_timeout));
            replaced = std::move(parked_[{path, endpoint}]);
            parked_[{path, endpoint}] = parked;
        }
    }
    if (replaced && !replaced->responder.done()) answer(replaced->responder, "Continue");
    if (!parked->timer) answer(parked->responder, granted_meanwhile ? "OK" : "Continue");  // no io_context: the client asks again at once
}

void ServiceLocks::deliver(std::vector<ObjectLocks::MonitorEvent>& events) {
    bool granted = false;
    for (const auto& ev : events) {
        granted |= ev.granted;
        std::shared_ptr<Parked> p;
        {
            std::lock_guard lock(mutex_);
            auto it = parked_.find({ev.path, ev.endpoint});
            if (it == parked_.end()) continue;  // not parked: its next MonitorContinueEnter learns it
            p = std::move(it->second);
            parked_.erase(it);
        }
        if (p->timer) p->timer->cancel();
        if (p->responder.done()) continue;
        if (ev.granted)
            answer(p->responder, "OK");
        else
            p->responder.fail(make_error(MessageErrorType::RequestTimeout, "Timed out waiting for the monitor lock"));
    }
    events.clear();
    if (granted) changed();
}

}  // namespace rr::server
