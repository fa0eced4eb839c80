// TokenBucket: a rate limiter fed with time by its caller (sans-IO: no clock, no thread, no socket).
// Used by the gateway's listeners to cap each connection's messages/s and bytes/s (docs/security.md
// §Connection limits): the connection asks how long to pause its reads before it may take more.
//
// The bucket holds up to `burst` tokens and refills at `rate` tokens per second. take(n, now) spends n
// tokens; a take larger than what is left drives the level negative (a debt), and the caller is told
// how long to wait until the level is back at zero. A message bigger than the burst is still let
// through (the limiter slows a peer down, it never refuses a single message); its whole size is paid
// back by waiting, so the average over time stays at `rate` whatever the message sizes.
#pragma once

#include <chrono>
#include <cstdint>

namespace rr::server {

class TokenBucket {
public:
    using Clock = std::chrono::steady_clock;

    /// rate: tokens per second (0 = unlimited: take() never asks to wait). burst: the most tokens
    /// saved up while idle (0 = one second's worth of `rate`). The bucket starts full at `now`.
    TokenBucket(std::uint64_t rate, std::uint64_t burst, Clock::time_point now) noexcept;
    TokenBucket() noexcept : TokenBucket(0, 0, Clock::time_point{}) {}

    /// Spends `n` tokens at time `now` (which must not go backwards; an earlier time counts as `now`
    /// of the previous call). Returns how long the caller should wait before taking more: zero when
    /// the bucket still has tokens, else the time the refill needs to pay the debt back.
    std::chrono::nanoseconds take(std::uint64_t n, Clock::time_point now) noexcept;

    /// How long to wait at `now` before the level is back at zero (zero when not in debt).
    std::chrono::nanoseconds wait_time(Clock::time_point now) noexcept;

    /// Tokens available at `now` (negative: debt). Refills first.
    double level(Clock::time_point now) noexcept;

    bool unlimited() const noexcept { return rate_ == 0; }
    std::uint64_t rate() const noexcept { return rate_; }
    std::uint64_t burst() const noexcept { return burst_; }

private:
    void refill(Clock::time_point now) noexcept;
    std::chrono::nanoseconds debt_time() const noexcept;

    std::uint64_t rate_;
    std::uint64_t burst_;
    double level_;
    Clock::time_point last_;
};

}  // namespace rr::server
