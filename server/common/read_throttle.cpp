#include "server/common/read_throttle.hpp"

#include <algorithm>
#include <cstring>

namespace rr::server {

std::uint64_t RrMessageCounter::feed(std::span<const std::byte> bytes) noexcept {
    std::uint64_t count = 0;
    while (!bytes.empty()) {
        if (skip_) {
            const auto n = static_cast<std::size_t>(std::min<std::uint64_t>(skip_, bytes.size()));
            skip_ -= n;
            bytes = bytes.subspan(n);
            continue;
        }
        const std::size_t n = std::min(head_.size() - have_, bytes.size());
        std::memcpy(head_.data() + have_, bytes.data(), n);
        have_ += n;
        bytes = bytes.subspan(n);
        if (have_ < head_.size()) break;
        have_ = 0;
        ++count;
        std::uint32_t size = 0;
        for (int i = 3; i >= 0; --i) size = (size << 8) | std::to_integer<std::uint32_t>(head_[4 + i]);
        skip_ = size > head_.size() ? size - head_.size() : 0;
    }
    return count;
}

ReadThrottle::ReadThrottle(const ReadRates& rates, Clock::time_point now) noexcept
    : messages_(rates.messages_per_second, rates.messages_per_second * std::max(1u, rates.burst_s), now),
      bytes_(rates.bytes_per_second, rates.bytes_per_second * std::max(1u, rates.burst_s), now) {}

std::chrono::nanoseconds ReadThrottle::charge(std::span<const std::byte> bytes, Clock::time_point now) noexcept {
    std::chrono::nanoseconds wait{0};
    if (!messages_.unlimited()) wait = std::max(wait, messages_.take(counter_.feed(bytes), now));
    if (!bytes_.unlimited()) wait = std::max(wait, bytes_.take(bytes.size(), now));
    return wait;
}

std::chrono::nanoseconds ReadThrottle::charge_message(std::uint64_t size, Clock::time_point now) noexcept {
    std::chrono::nanoseconds wait{0};
    if (!messages_.unlimited()) wait = std::max(wait, messages_.take(1, now));
    if (!bytes_.unlimited()) wait = std::max(wait, bytes_.take(size, now));
    return wait;
}

}  // namespace rr::server
