// What one JSON socket may have waiting for conversion to JSON (pipe packets on the shared conversion
// strand, server/gateway/json_socket.hpp): at most `max_count` packets and `max_bytes` of their
// payload. A packet larger than `max_bytes` alone still goes when nothing else waits, so a big camera
// frame is never refused outright. Thread-safe.
#pragma once

#include <cstddef>
#include <mutex>

#include "base/message/message.hpp"

namespace rr::server::gateway {

class ConversionBudget {
public:
    ConversionBudget(std::size_t max_count, std::size_t max_bytes) : max_count_(max_count), max_bytes_(max_bytes) {}

    /// Reserves room for a packet of `bytes`; false (nothing reserved) when the budget is spent.
    bool try_acquire(std::size_t bytes) {
        std::lock_guard lock(mutex_);
        if (count_ >= max_count_) return false;
        if (count_ > 0 && bytes > max_bytes_ - std::min(bytes_, max_bytes_)) return false;
        ++count_;
        bytes_ += bytes;
        return true;
    }
    /// Returns what try_acquire(bytes) reserved.
    void release(std::size_t bytes) {
        std::lock_guard lock(mutex_);
        --count_;
        bytes_ -= bytes;
    }
    std::size_t waiting() const {
        std::lock_guard lock(mutex_);
        return count_;
    }

private:
    const std::size_t max_count_, max_bytes_;
    mutable std::mutex mutex_;
    std::size_t count_ = 0, bytes_ = 0;
};

/// The payload bytes an element holds, its children's included (what a waiting packet keeps alive).
inline std::size_t payload_bytes(const MessageElement& e) {
    std::size_t n = e.data.size();
    for (const auto& c : e.elements) n += payload_bytes(c);
    return n;
}

}  // namespace rr::server::gateway
