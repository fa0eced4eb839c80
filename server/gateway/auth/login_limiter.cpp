#include "server/gateway/auth/login_limiter.hpp"

#include <algorithm>

namespace rr::server::gateway::auth {

std::int64_t LoginLimiter::blocked_for(std::string_view address, Clock::time_point now) const {
    std::lock_guard lock(mutex_);
    auto it = entries_.find(address);
    if (it == entries_.end() || it->second.locked_until <= now) return 0;
    auto left = std::chrono::ceil<std::chrono::seconds>(it->second.locked_until - now).count();
    return std::max<std::int64_t>(1, left);
}

bool LoginLimiter::failed(std::string_view address, Clock::time_point now) {
    std::lock_guard lock(mutex_);
    auto it = entries_.find(address);
    if (it == entries_.end()) {
        if (entries_.size() >= limits_.max_addresses) {
            // Evict the entry seen longest ago (linear, only when full).
            auto oldest = std::min_element(entries_.begin(), entries_.end(),
                                           [](const auto& a, const auto& b) { return a.second.last < b.second.last; });
            entries_.erase(oldest);
        }
        it = entries_.emplace(std::string(address), Entry{}).first;
    }
    Entry& e = it->second;
    if (e.failures == 0 || now - e.first > limits_.window) {
        e.failures = 0;
        e.first = now;
    }
    e.last = now;
    ++e.failures;
    if (e.failures >= limits_.max_failures && limits_.max_failures > 0) {
        e.locked_until = now + limits_.lockout;
        e.failures = 0;
        return true;
    }
    return false;
}

void LoginLimiter::succeeded(std::string_view address) {
    std::lock_guard lock(mutex_);
    if (auto it = entries_.find(address); it != entries_.end()) entries_.erase(it);
}

std::size_t LoginLimiter::tracked() const {
    std::lock_guard lock(mutex_);
    return entries_.size();
}

std::string address_of(std::string_view peer) {
    if (!peer.empty() && peer.front() == '[') {
        auto close = peer.find(']');
        if (close != std::string_view::npos) return std::string(peer.substr(1, close - 1));
    }
    // One colon: "ip:port". Several colons without brackets: a bare IPv6 address.
    auto first = peer.find(':');
    if (first != std::string_view::npos && peer.find(':', first + 1) == std::string_view::npos)
        return std::string(peer.substr(0, first));
    return std::string(peer);
}

}  // namespace rr::server::gateway::auth
