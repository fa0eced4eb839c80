#include "server/demo/periodic_task.hpp"

#include <boost/asio/post.hpp>

namespace rr::server::demo {

namespace asio = boost::asio;

PeriodicTask::PeriodicTask(asio::io_context& io, std::chrono::nanoseconds period, Tick tick)
    : strand_(asio::make_strand(io)), timer_(strand_), period_(period), tick_(std::move(tick)) {}

std::shared_ptr<PeriodicTask> PeriodicTask::start(asio::io_context& io, std::chrono::nanoseconds period, Tick tick) {
    std::shared_ptr<PeriodicTask> task(new PeriodicTask(io, period, std::move(tick)));
    asio::post(task->strand_, [weak = task->weak_from_this()] {
        auto self = weak.lock();
        if (!self || self->stopped_) return;
        self->next_ = self->last_ = std::chrono::steady_clock::now();
        self->schedule();
    });
    return task;
}

void PeriodicTask::schedule() {
    const auto now = std::chrono::steady_clock::now();
    next_ += period_;
    if (next_ < now) next_ = now;
    timer_.expires_at(next_);
    timer_.async_wait([weak = weak_from_this()](boost::system::error_code ec) {
        if (ec) return;
        auto self = weak.lock();
        if (!self || self->stopped_) return;
        const auto now = std::chrono::steady_clock::now();
        const auto elapsed = std::chrono::duration_cast<std::chrono::nanoseconds>(now - self->last_);
        self->last_ = now;
        self->tick_(elapsed);
        self->schedule();
    });
}

void PeriodicTask::stop() {
    asio::post(strand_, [weak = weak_from_this()] {
        auto self = weak.lock();
        if (!self) return;
        self->stopped_ = true;
        self->timer_.cancel();
    });
}

}  // namespace rr::server::demo
