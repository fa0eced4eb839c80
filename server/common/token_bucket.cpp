#include "server/common/token_bucket.hpp"

#include <algorithm>
#include <cmath>

namespace rr::server {

TokenBucket::TokenBucket(std::uint64_t rate, std::uint64_t burst, Clock::time_point now) noexcept
    : rate_(rate), burst_(burst ? burst : rate), level_(static_cast<double>(burst ? burst : rate)), last_(now) {}

void TokenBucket::refill(Clock::time_point now) noexcept {
    if (now <= last_) return;
    const double seconds = std::chrono::duration<double>(now - last_).count();
    level_ = std::min(static_cast<double>(burst_), level_ + seconds * static_cast<double>(rate_));
    last_ = now;
}

std::chrono::nanoseconds TokenBucket::debt_time() const noexcept {
    if (level_ >= 0 || rate_ == 0) return std::chrono::nanoseconds{0};
    const double ns = std::ceil(-level_ * 1e9 / static_cast<double>(rate_));
    return std::chrono::nanoseconds{static_cast<std::int64_t>(ns)};
}

std::chrono::nanoseconds TokenBucket::take(std::uint64_t n, Clock::time_point now) noexcept {
    if (rate_ == 0) return std::chrono::nanoseconds{0};
    refill(now);
    level_ -= static_cast<double>(n);
    return debt_time();
}

std::chrono::nanoseconds TokenBucket::wait_time(Clock::time_point now) noexcept {
    if (rate_ == 0) return std::chrono::nanoseconds{0};
    refill(now);
    return debt_time();
}

double TokenBucket::level(Clock::time_point now) noexcept {
    refill(now);
    return level_;
}

}  // namespace rr::server
