// The timers of rate-limited subscriptions (rate_window.hpp), one per rate: every JSON socket with a
// value waiting for the next window of period P asks this to wake it then; at that window's start the
// one timer of P wakes all of them, and they send the newest value they hold. Rate-limited pipes wait
// here; rate-limited wires are handed their values by their rate group (wire_rate_groups.hpp, no
// registration per socket and window) and come here only when a value reaches the socket after its
// window already had one (a slow socket's late write). A rate with nobody waiting has no timer.
// Thread-safe.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <vector>

#include <boost/asio/any_io_executor.hpp>
#include <boost/asio/steady_timer.hpp>

#include "server/gateway/rate_window.hpp"

namespace rr::server::gateway {

/// The steady clock as RateWindow counts it (the grid of windows is on this clock, as the timers are).
RateClock rate_clock_now();

class RateTicker : public std::enable_shared_from_this<RateTicker> {
public:
    explicit RateTicker(boost::asio::any_io_executor executor) : executor_(std::move(executor)) {}

    /// Calls `wake` once at the start of the next window of `period` (after now), on the executor.
    void wake(RateClock period, std::function<void()> wake);
    /// Rates with a timer armed now (for tests).
    std::size_t armed() const;

private:
    struct Group {
        std::unique_ptr<boost::asio::steady_timer> timer;
        std::vector<std::function<void()>> waiting;
    };
    void fire(RateClock period);

    boost::asio::any_io_executor executor_;
    mutable std::mutex mutex_;
    std::map<RateClock, Group> groups_;
};

}  // namespace rr::server::gateway
