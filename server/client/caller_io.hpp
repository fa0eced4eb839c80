// Threads that run a client's io_context while they wait (ClientOptions::caller_runs_io), and how one
// of them waits without a timeout.
//
// A wait with a timeout arms a kernel timer on every call (epoll_wait's timeout, re-armed per call),
// and on the VMs this project runs on that costs more CPU than the rest of the call: a blocking Nop
// with caller_runs_io took 13–18 µs of the client's CPU with 1 ms slices against 6.9 µs with an
// untimed wait, and 7.3 µs for the asynchronous layer (issue 14, docs/benchmarks.md). So a thread that
// runs the io_context alone and waits for a call's answer blocks in the socket wait without a timeout.
// As soon as a second thread runs the io_context too, every waiter uses 1 ms slices: Asio may then run
// one thread's completion on the other while the first sleeps where no event would wake it. The
// thread that arrives second first wakes the untimed one (a posted no-op nobody else can take, since
// it does not run the io_context yet) and waits until it has left the untimed wait.
//
// A result set by a thread that does not run the io_context (a blocking caller's own work run inline
// on the strand, such as close(), or a completion destroyed unanswered) wakes the untimed waiter the
// same way: `UntimedWait::kick()`.
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <thread>
#include <utility>

#include <boost/asio/execution_context.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>

namespace rr::client::detail {

/// Per io_context: how many threads run it from a caller-runs wait, and whether one of them is in an
/// untimed wait (Asio service: one per io_context, made on first use).
class CallerIoRunners : public boost::asio::execution_context::service {
public:
    using key_type = CallerIoRunners;
    inline static boost::asio::execution_context::id id;
    explicit CallerIoRunners(boost::asio::execution_context& context) : service(context) {}
    /// The io_context it belongs to (made only by use_service on an io_context).
    boost::asio::io_context& io() noexcept { return static_cast<boost::asio::io_context&>(context()); }

    std::atomic<int> runners{0};
    std::atomic<bool> untimed{false};
    /// Threads that run the io_context for good (IoThreads' workers): while any do, nobody waits untimed.
    std::atomic<int> workers{0};

private:
    void shutdown() override {}
};

/// A waiter's side of the untimed wait, made on the waiting thread: active while that thread may block
/// in the io_context without a timeout, so that a result set from elsewhere wakes it.
class UntimedWait {
public:
    /// Called by whoever sets the waiter's result, after setting it.
    void kick() const {
        if (!active_.load()) return;
        if (thread_ == std::this_thread::get_id()) return;  // the waiter itself: it returns on its own
        if (auto* io = io_.load()) boost::asio::post(*io, [] {});
    }

    /// The waiting thread, around one untimed run of `io`.
    void enter(boost::asio::io_context& io) {
        io_.store(&io);
        active_.store(true);
    }
    void leave() { active_.store(false); }

private:
    const std::thread::id thread_ = std::this_thread::get_id();
    std::atomic<bool> active_{false};
    std::atomic<boost::asio::io_context*> io_{nullptr};
};

/// The runners of `io` (a lookup under Asio's service registry lock: a client keeps the answer).
inline CallerIoRunners& caller_io_runners(boost::asio::io_context& io) { return boost::asio::use_service<CallerIoRunners>(io); }

/// Counts this thread among `runners`; when a thread waits there untimed, wakes it and waits until it
/// has left that wait (header comment).
inline void join_runners(CallerIoRunners& runners) {
    if (runners.runners.fetch_add(1) > 0 && runners.untimed.load()) {
        boost::asio::post(runners.io(), [] {});
        while (runners.untimed.load()) std::this_thread::sleep_for(std::chrono::microseconds(20));
    }
}

/// One run of `io` of at most `slice`. When it is out of work (no worker guard) nothing here can
/// finish it: a short sleep instead of a spin.
inline void run_slice(boost::asio::io_context& io, std::chrono::steady_clock::duration slice) {
    if (io.run_one_for(slice) == 0 && io.stopped()) {
        io.restart();
        std::this_thread::sleep_for(std::min<std::chrono::steady_clock::duration>(slice, std::chrono::microseconds(100)));
    }
}

/// Runs the io_context of `runners` on this thread until `done()` or `deadline`. In slices of at most 1 ms (another thread
/// may complete what this one waits for), unless `untimed` is given (one blocking call's answer, whose
/// setter kicks it) and this is the only thread running `io`: then without a timeout, and `deadline`
/// is checked whenever a handler ran (the connection's own timers, heartbeat and request timeout, run
/// at least that often). True when done.
template <class Done>
bool run_io_until(CallerIoRunners& runners, Done done, std::chrono::steady_clock::time_point deadline,
                  UntimedWait* untimed = nullptr) {
    boost::asio::io_context& io = runners.io();
    join_runners(runners);
    bool ok = true;
    while (!done()) {
        const auto now = std::chrono::steady_clock::now();
        if (now >= deadline) {
            ok = false;
            break;
        }
        bool alone = false;
        if (untimed) {
            // Announce, then look; the arriving thread and the result's setter do the reverse: one of
            // the two sees the other, so nobody is left asleep (sequentially consistent atomics).
            runners.untimed.store(true);
            untimed->enter(io);
            alone = runners.runners.load() == 1 && runners.workers.load() == 0;
            std::size_t ran = 1;
            if (alone && !done()) ran = io.run_one();
            untimed->leave();
            runners.untimed.store(false);
            if (alone && ran == 0 && io.stopped()) run_slice(io, std::chrono::milliseconds(1));  // restarts it, no spin
        }
        if (!alone)
            run_slice(io, std::min<std::chrono::steady_clock::duration>(deadline - now, std::chrono::milliseconds(1)));
    }
    runners.runners.fetch_sub(1);
    return ok;
}

/// The same for `io` (looks its runners up).
template <class Done>
bool run_io_until(boost::asio::io_context& io, Done done, std::chrono::steady_clock::time_point deadline,
                  UntimedWait* untimed = nullptr) {
    return run_io_until(caller_io_runners(io), std::move(done), deadline, untimed);
}

}  // namespace rr::client::detail
