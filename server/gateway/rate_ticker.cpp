#include "server/gateway/rate_ticker.hpp"

#include <chrono>

namespace rr::server::gateway {

RateClock rate_clock_now() {
    return std::chrono::duration_cast<RateClock>(std::chrono::steady_clock::now().time_since_epoch());
}

void RateTicker::wake(RateClock period, std::function<void()> wake) {
    std::lock_guard lock(mutex_);
    auto& g = groups_[period];
    g.waiting.push_back(std::move(wake));
    if (g.timer) return;  // armed: its window's start wakes this one too
    g.timer = std::make_unique<boost::asio::steady_timer>(executor_);
    const RateClock start = RateWindow(period).window_start(rate_clock_now()) + period;
    g.timer->expires_at(std::chrono::steady_clock::time_point(std::chrono::duration_cast<std::chrono::steady_clock::duration>(start)));
    std::weak_ptr<RateTicker> weak = weak_from_this();
    g.timer->async_wait([weak, period](boost::system::error_code ec) {
        if (auto self = weak.lock(); self && !ec) self->fire(period);
    });
}

void RateTicker::fire(RateClock period) {
    std::vector<std::function<void()>> waiting;
    std::unique_ptr<boost::asio::steady_timer> done;
    {
        std::lock_guard lock(mutex_);
        auto it = groups_.find(period);
        if (it == groups_.end()) return;
        waiting.swap(it->second.waiting);
        done = std::move(it->second.timer);  // its wait has ended; destroyed outside the lock
        groups_.erase(it);
    }
    for (auto& w : waiting) w();
}

std::size_t RateTicker::armed() const {
    std::lock_guard lock(mutex_);
    return groups_.size();
}

}  // namespace rr::server::gateway
