// CallerRunsExecutor: a strand over it runs a dispatch from a CallerRunsExecutor::Scope on the
// calling thread when idle, and otherwise behaves as a plain strand.
#include <catch2/catch.hpp>

#include <atomic>
#include <future>
#include <thread>

#include <boost/asio/any_io_executor.hpp>
#include <boost/asio/dispatch.hpp>
#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/strand.hpp>

#include "server/common/caller_runs_executor.hpp"

namespace asio = boost::asio;
using rr::server::CallerRunsExecutor;

namespace {

struct Worker {
    asio::io_context io;
    asio::executor_work_guard<asio::io_context::executor_type> guard{io.get_executor()};
    std::thread thread{[this] { io.run(); }};
    ~Worker() {
        guard.reset();
        io.stop();
        thread.join();
    }
};

// The thread a dispatch to `strand` ran on (waits for it).
template <class Strand>
std::thread::id dispatched_on(const Strand& strand) {
    std::promise<std::thread::id> ran;
    auto f = ran.get_future();
    asio::any_io_executor ex = strand;  // as StreamPump holds it
    asio::dispatch(ex, [&ran] { ran.set_value(std::this_thread::get_id()); });
    return f.get();
}

}  // namespace

TEST_CASE("caller runs executor: inside a scope an idle strand runs the dispatch on the calling thread") {
    Worker w;
    auto strand = asio::make_strand(CallerRunsExecutor(w.io.get_executor()));
    CallerRunsExecutor::Scope scope;
    CHECK(dispatched_on(strand) == std::this_thread::get_id());
    CHECK(scope.used());
}

TEST_CASE("caller runs executor: outside a scope a dispatch goes to the worker thread") {
    Worker w;
    auto strand = asio::make_strand(CallerRunsExecutor(w.io.get_executor()));
    CHECK(dispatched_on(strand) == w.thread.get_id());
}

TEST_CASE("caller runs executor: a scope serves one dispatch, and what that work posts runs on the worker") {
    Worker w;
    auto strand = asio::make_strand(CallerRunsExecutor(w.io.get_executor()));
    asio::any_io_executor ex = strand;
    std::promise<std::thread::id> inner;
    std::thread::id outer;
    {
        CallerRunsExecutor::Scope scope;
        asio::dispatch(ex, [&] {
            outer = std::this_thread::get_id();
            // Still inside the strand: posted work queues behind it and goes to the worker.
            asio::post(ex, [&inner] { inner.set_value(std::this_thread::get_id()); });
        });
    }
    CHECK(outer == std::this_thread::get_id());
    CHECK(inner.get_future().get() == w.thread.get_id());
}

TEST_CASE("caller runs executor: a scope is used up by its first dispatch") {
    Worker w;
    auto strand = asio::make_strand(CallerRunsExecutor(w.io.get_executor()));
    CallerRunsExecutor::Scope scope;
    CHECK(dispatched_on(strand) == std::this_thread::get_id());
    CHECK(dispatched_on(strand) == w.thread.get_id());
}

TEST_CASE("caller runs executor: a busy strand is not entered, the work runs after the holder on the worker") {
    Worker w;
    auto strand = asio::make_strand(CallerRunsExecutor(w.io.get_executor()));
    asio::any_io_executor ex = strand;
    std::promise<void> holding, release;
    auto released = release.get_future().share();
    asio::post(ex, [&holding, released] {
        holding.set_value();
        released.wait();
    });
    holding.get_future().wait();
    std::atomic<bool> ran{false};
    std::promise<std::thread::id> where;
    {
        CallerRunsExecutor::Scope scope;
        asio::dispatch(ex, [&] {
            ran = true;
            where.set_value(std::this_thread::get_id());
        });
        CHECK_FALSE(scope.used());
    }
    CHECK_FALSE(ran.load());  // queued behind the holder, not run by this thread
    release.set_value();
    CHECK(where.get_future().get() == w.thread.get_id());
}
