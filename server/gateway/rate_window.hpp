// A subscription's maximum rate (docs/json-api.md "Rate and queue length"): at most one value per
// window of 1/max_rate_hz, the windows on one grid shared by every subscription of that rate (they
// start at whole multiples of the period on the steady clock), so subscribers at the same rate send at
// the same instants, the same value (one rendering, shared_entry.hpp), woken by one timer.
// Sans-IO: the caller passes the time; nothing here reads a clock.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>

namespace rr::server::gateway {

using RateClock = std::chrono::nanoseconds;  ///< a steady clock's time since its epoch

inline constexpr double kMinRateHz = 0.01;    ///< one value per 100 s
inline constexpr double kMaxRateHz = 1000.0;  ///< one value per millisecond

/// The period of `hz`, or the reason it is refused: not a number, not in [kMinRateHz, kMaxRateHz].
struct RatePeriod {
    RateClock period{0};
    std::string error;  ///< empty when `period` is valid
};
RatePeriod rate_period(double hz);

class RateWindow {
public:
    RateWindow() = default;  ///< no limit: always open
    explicit RateWindow(RateClock period) : period_(period) {}

    bool limited() const noexcept { return period_.count() > 0; }
    RateClock period() const noexcept { return period_; }

    /// Whether a value may be sent at `now` (no value sent yet in the window `now` is in).
    bool open(RateClock now) const noexcept { return !limited() || now >= next_open_; }
    /// A value was sent at `now`: the next may go from the start of the next window.
    void sent(RateClock now) noexcept {
        if (limited()) next_open_ = window_start(now) + period_;
    }
    /// When a waiting value may go (a window's start; the past when open now).
    RateClock next_open() const noexcept { return next_open_; }

    /// The start of the window `t` is in.
    RateClock window_start(RateClock t) const noexcept {
        if (!limited()) return t;
        const auto n = t.count() / period_.count();
        return RateClock(n * period_.count());
    }

private:
    RateClock period_{0};
    RateClock next_open_{0};
};

}  // namespace rr::server::gateway
