// The demo devices' real-time driver: calls `tick(elapsed)` every `period` on a strand of its own, at a
// fixed cadence re-based when more than a period late (a stall gives no burst of catch-up ticks), until
// stop(). `elapsed` is the time since the previous tick (the first: since start()).
#pragma once

#include <chrono>
#include <functional>
#include <memory>

#include <boost/asio/io_context.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>

namespace rr::server::demo {

class PeriodicTask : public std::enable_shared_from_this<PeriodicTask> {
public:
    using Tick = std::function<void(std::chrono::nanoseconds elapsed)>;

    /// Starts ticking on `io`; the first tick is one period away. The task stops by itself when the
    /// last shared_ptr to it goes; `tick` must not own it.
    static std::shared_ptr<PeriodicTask> start(boost::asio::io_context& io, std::chrono::nanoseconds period, Tick tick);
    /// No tick starts once the stop has run on the strand (asynchronous; safe from any thread).
    void stop();

private:
    using Strand = boost::asio::strand<boost::asio::io_context::executor_type>;
    PeriodicTask(boost::asio::io_context& io, std::chrono::nanoseconds period, Tick tick);
    void schedule();

    Strand strand_;
    boost::asio::steady_timer timer_;
    const std::chrono::nanoseconds period_;
    const Tick tick_;
    std::chrono::steady_clock::time_point next_, last_;  // touched only on strand_
    bool stopped_ = false;
};

}  // namespace rr::server::demo
