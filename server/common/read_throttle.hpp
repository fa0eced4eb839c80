// ReadThrottle: paces what one connection may send (gateway.limits.messages_per_second and
// bytes_per_second, docs/security.md "Connection limits"). Sans-IO: the caller feeds it the bytes it
// read and the time, and gets back how long to pause reading before the next read. A peer over its
// rate is slowed down by TCP back-pressure (its reads paused), never disconnected.
//
// For RR byte streams, messages are counted from the RR stream framing (wire.md §1.2: every message starts with `RRAC` and a
// uint32 little-endian total size), so a message split across reads is counted once, when its header
// is complete. The count does not validate anything: a peer that breaks the framing is closed by the
// protocol logic, not here.
#pragma once

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <span>

#include "server/common/token_bucket.hpp"

namespace rr::server {

/// Per-connection rates; 0 = unlimited.
struct ReadRates {
    std::uint64_t messages_per_second = 0;
    std::uint64_t bytes_per_second = 0;
    /// Seconds of each rate a connection may save up while quiet (its burst), at least 1.
    unsigned burst_s = 1;
    bool enabled() const noexcept { return messages_per_second != 0 || bytes_per_second != 0; }
};

/// Counts RR messages in a byte stream (wire.md §1.2 framing) without buffering them.
class RrMessageCounter {
public:
    /// Messages whose 8-byte header (magic and size) completes within `bytes`.
    std::uint64_t feed(std::span<const std::byte> bytes) noexcept;

private:
    std::uint64_t skip_ = 0;  // bytes left of the current message's body
    std::array<std::byte, 8> head_{};
    std::size_t have_ = 0;    // header bytes collected so far
};

class ReadThrottle {
public:
    using Clock = TokenBucket::Clock;

    ReadThrottle(const ReadRates& rates, Clock::time_point now) noexcept;

    /// Charges `bytes` just read at `now`; returns how long to pause reading (zero: read on).
    std::chrono::nanoseconds charge(std::span<const std::byte> bytes, Clock::time_point now) noexcept;
    /// Charges one whole message of `size` bytes, for protocols whose framing the caller parsed itself
    /// (an HTTP request, a JSON WebSocket message); returns how long to pause before the next read.
    std::chrono::nanoseconds charge_message(std::uint64_t size, Clock::time_point now) noexcept;

private:
    TokenBucket messages_;
    TokenBucket bytes_;
    RrMessageCounter counter_;
};

}  // namespace rr::server
