#include "server/service/object_locks.hpp"

#include <algorithm>

namespace rr::server {

namespace {

RRError locked(std::string message) { return make_error(MessageErrorType::ObjectLockedError, std::move(message)); }

}  // namespace

bool ObjectLocks::covers(std::string_view ancestor, std::string_view path) noexcept {
    if (path.size() < ancestor.size() || path.compare(0, ancestor.size(), ancestor) != 0) return false;
    if (path.size() == ancestor.size()) return true;
    const char next = path[ancestor.size()];
    return next == '.' || next == '[';
}

// --- object locks ---------------------------------------------------------------------------

Result<void> ObjectLocks::lock(const std::string& path, const std::string& username, std::uint32_t endpoint) {
    for (const auto& [p, h] : locks_)
        if (covers(p, path) || covers(path, p)) return fail(locked("Object already locked"));
    locks_.emplace(path, Holder{path, username, endpoint});
    return {};
}

std::optional<ObjectLocks::Holder> ObjectLocks::holder(std::string_view path) const {
    for (const auto& [p, h] : locks_)
        if (covers(p, path)) return h;
    return std::nullopt;
}

Result<void> ObjectLocks::release(const std::string& path, const std::string& username, std::uint32_t endpoint,
                                  bool override_) {
    auto h = holder(path);
    if (!h) return {};
    if (h->path != path) return fail(locked("Cannot release inherited lock"));
    if (h->username != username && !override_) return fail(locked("Service locked by user " + h->username));
    // A client lock of the same user may be released from another of the user's sessions (as CORE).
    (void)endpoint;
    locks_.erase(path);
    return {};
}

Result<void> ObjectLocks::check(std::string_view path, std::string_view username, std::uint32_t endpoint) const {
    auto h = holder(path);
    if (!h) return {};
    if (!username.empty() && h->username == username && (h->endpoint == 0 || h->endpoint == endpoint)) return {};
    return fail(locked("Object locked by " + h->username));
}

std::vector<ObjectLocks::Holder> ObjectLocks::locks() const {
    std::vector<Holder> out;
    out.reserve(locks_.size());
    for (const auto& [p, h] : locks_) out.push_back(h);
    return out;
}

void ObjectLocks::session_closed(std::uint32_t endpoint, std::string_view username, bool last_session_of_user) {
    for (auto it = locks_.begin(); it != locks_.end();) {
        const Holder& h = it->second;
        const bool drop = (h.endpoint != 0 && h.endpoint == endpoint) ||
                          (h.endpoint == 0 && !username.empty() && h.username == username && last_session_of_user);
        it = drop ? locks_.erase(it) : std::next(it);
    }
}

// --- monitor locks --------------------------------------------------------------------------

void ObjectLocks::settle(std::map<std::string, Monitor>::iterator it, Clock::time_point now,
                         std::vector<MonitorEvent>& events) {
    Monitor& m = it->second;
    if (m.holder != 0 && now - m.last_use >= kMonitorIdle) m.holder = 0;
    for (auto w = m.waiters.begin(); w != m.waiters.end();) {
        if (w->deadline && now >= *w->deadline) {
            events.push_back(MonitorEvent{it->first, w->endpoint, false});
            w = m.waiters.erase(w);
        } else {
            ++w;
        }
    }
    if (m.holder == 0 && !m.waiters.empty()) {
        m.holder = m.waiters.front().endpoint;
        m.last_use = now;
        m.waiters.pop_front();
        events.push_back(MonitorEvent{it->first, m.holder, true});
    }
    if (m.holder == 0 && m.waiters.empty()) monitors_.erase(it);
}

Result<bool> ObjectLocks::monitor_enter(const std::string& path, std::uint32_t endpoint, std::int32_t timeout_ms,
                                        Clock::time_point now, std::vector<MonitorEvent>& events) {
    auto it = monitors_.find(path);
    if (it != monitors_.end()) {
        settle(it, now, events);
        it = monitors_.find(path);
    }
    if (it == monitors_.end()) {
        Monitor m;
        m.holder = endpoint;
        m.last_use = now;
        monitors_.emplace(path, std::move(m));
        return true;
    }
    Monitor& m = it->second;
    const bool waiting = std::any_of(m.waiters.begin(), m.waiters.end(), [&](const Waiter& w) { return w.endpoint == endpoint; });
    if (m.holder == endpoint || waiting)
        return fail(MessageErrorType::InvalidOperation, "Already acquiring or acquired monitor lock");
    Waiter w{endpoint, std::nullopt};
    if (timeout_ms >= 0) w.deadline = now + std::chrono::milliseconds(timeout_ms);
    m.waiters.push_back(w);
    return false;
}

Result<bool> ObjectLocks::monitor_continue(const std::string& path, std::uint32_t endpoint, Clock::time_point now,
                                           std::vector<MonitorEvent>& events) {
    auto it = monitors_.find(path);
    if (it == monitors_.end()) return fail(MessageErrorType::InvalidOperation, "Not acquiring monitor lock");
    Monitor& m = it->second;
    if (m.holder == endpoint && now - m.last_use < kMonitorIdle) {
        m.last_use = now;
        return true;
    }
    auto w = std::find_if(m.waiters.begin(), m.waiters.end(), [&](const Waiter& x) { return x.endpoint == endpoint; });
    if (w == m.waiters.end()) {
        settle(it, now, events);
        return fail(MessageErrorType::InvalidOperation, "Not acquiring monitor lock");
    }
    if (w->deadline && now >= *w->deadline) {
        m.waiters.erase(w);
        settle(it, now, events);
        return fail(MessageErrorType::RequestTimeout, "Timed out waiting for the monitor lock");
    }
    settle(it, now, events);
    it = monitors_.find(path);
    return it != monitors_.end() && it->second.holder == endpoint;
}

Result<void> ObjectLocks::monitor_exit(const std::string& path, std::uint32_t endpoint, Clock::time_point now,
                                       std::vector<MonitorEvent>& events) {
    auto it = monitors_.find(path);
    if (it == monitors_.end()) return {};
    Monitor& m = it->second;
    if (m.holder == endpoint) {
        m.holder = 0;
    } else {
        auto w = std::find_if(m.waiters.begin(), m.waiters.end(), [&](const Waiter& x) { return x.endpoint == endpoint; });
        if (w == m.waiters.end()) {
            settle(it, now, events);
            return fail(MessageErrorType::InvalidOperation, "Not monitor locked");
        }
        m.waiters.erase(w);
    }
    settle(it, now, events);
    return {};
}

Result<void> ObjectLocks::monitor_check(const std::string& path, std::uint32_t endpoint, Clock::time_point now,
                                        std::vector<MonitorEvent>& events) {
    auto it = monitors_.find(path);
    if (it == monitors_.end()) return {};
    settle(it, now, events);
    it = monitors_.find(path);
    if (it == monitors_.end() || it->second.holder == 0) return {};
    if (it->second.holder == endpoint) {
        it->second.last_use = now;
        return {};
    }
    return fail(MessageErrorType::InvalidOperation, "Object is currently monitor locked. Use MonitorEnter to obtain monitor lock");
}

void ObjectLocks::monitor_poll(Clock::time_point now, std::vector<MonitorEvent>& events) {
    for (auto it = monitors_.begin(); it != monitors_.end();) {
        auto next = std::next(it);
        settle(it, now, events);
        it = next;
    }
}

void ObjectLocks::monitor_session_closed(std::uint32_t endpoint, Clock::time_point now, std::vector<MonitorEvent>& events) {
    for (auto it = monitors_.begin(); it != monitors_.end();) {
        auto next = std::next(it);
        Monitor& m = it->second;
        if (m.holder == endpoint) m.holder = 0;
        m.waiters.erase(std::remove_if(m.waiters.begin(), m.waiters.end(), [&](const Waiter& w) { return w.endpoint == endpoint; }),
                        m.waiters.end());
        settle(it, now, events);
        it = next;
    }
}

std::uint32_t ObjectLocks::monitor_holder(const std::string& path) const {
    auto it = monitors_.find(path);
    return it == monitors_.end() ? 0 : it->second.holder;
}

std::optional<ObjectLocks::Clock::time_point> ObjectLocks::monitor_wait_deadline(const std::string& path,
                                                                                 std::uint32_t endpoint) const {
    auto it = monitors_.find(path);
    if (it == monitors_.end()) return std::nullopt;
    for (const auto& w : it->second.waiters)
        if (w.endpoint == endpoint) return w.deadline;
    return std::nullopt;
}

std::vector<std::pair<std::string, std::uint32_t>> ObjectLocks::monitor_holders(Clock::time_point now) const {
    std::vector<std::pair<std::string, std::uint32_t>> out;
    for (const auto& [path, m] : monitors_)
        if (m.holder != 0 && now - m.last_use < kMonitorIdle) out.emplace_back(path, m.holder);
    return out;
}

}  // namespace rr::server
