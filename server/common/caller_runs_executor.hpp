// An executor over another (an io_context's) that lets a thread about to block run a
// strand's work itself instead of waking a worker thread for it.
//
// A blocking client call hands its request to the connection's strand and waits for the reply. With a
// plain strand, the hand-over from a foreign thread is a post: a worker thread wakes only to encode
// the request and write it, and the caller wakes again for the reply (two cross-thread wake-ups per
// call, issue 14). A strand built over this executor (`asio::make_strand(CallerRunsExecutor(ex))`)
// runs the caller's function on the caller's own thread when, inside a CallerRunsExecutor::Scope, the caller
// dispatches to the strand and the strand is idle; the reply is then the call's one wake-up. The
// strand's guarantees hold: the function runs only while the strand is held by this thread, and work
// queued meanwhile is posted to the worker threads as usual (never-blocking execution).
// Outside a scope, or when the strand is busy, everything behaves as the inner executor does.
#pragma once

#include <concepts>
#include <type_traits>
#include <utility>

#include <boost/asio/execution.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/prefer.hpp>
#include <boost/asio/query.hpp>
#include <boost/asio/require.hpp>

namespace rr::server {

namespace detail {
/// The thread's "run the next possibly-blocking execute() inline" flag, shared by every inner type.
inline bool& caller_runs_armed() noexcept {
    thread_local bool flag = false;
    return flag;
}
}  // namespace detail

/// `Inner` is a concrete executor type, not `any_io_executor`: querying `blocking` through the
/// type-erased executor heap-allocates its answer, and a strand over a type-erased inner is too big
/// for `any_io_executor`'s in-place buffer, so every copy Asio makes of it would allocate too (issue 14,
/// bench/profile.sh).
template <class Inner>
class BasicCallerRunsExecutor {
public:
    using inner_type = Inner;

    // Constrained, not a plain converting constructor: checking whether this type is copyable must
    // not ask whether it converts to the inner type, which asks whether it is an executor (clang
    // reports the recursion as an error).
    template <class Other>
        requires(!std::same_as<std::decay_t<Other>, BasicCallerRunsExecutor> && std::constructible_from<inner_type, Other>)
    explicit BasicCallerRunsExecutor(Other&& inner) noexcept : inner_(std::forward<Other>(inner)) {}

    /// While alive, the next possibly-blocking execute() of a caller-runs executor on this thread runs
    /// the function inline (once: the scope is used up by it, so work the function starts is not
    /// also pulled onto this thread). Scopes do not nest.
    class Scope {
    public:
        Scope() noexcept { detail::caller_runs_armed() = true; }
        ~Scope() { detail::caller_runs_armed() = false; }
        Scope(const Scope&) = delete;
        Scope& operator=(const Scope&) = delete;
        /// True when the function ran inline on this thread.
        bool used() const noexcept { return !detail::caller_runs_armed(); }
    };

    template <class Property>
        requires boost::asio::can_query<const inner_type&, Property>::value
    decltype(auto) query(const Property& p) const {
        return boost::asio::query(inner_, p);
    }
    template <class Property>
        requires boost::asio::can_require<const inner_type&, Property>::value
    auto require(const Property& p) const {
        using Result = std::decay_t<decltype(boost::asio::require(inner_, p))>;
        return BasicCallerRunsExecutor<Result>(boost::asio::require(inner_, p));
    }
    template <class Property>
        requires boost::asio::can_prefer<const inner_type&, Property>::value
    auto prefer(const Property& p) const {
        using Result = std::decay_t<decltype(boost::asio::prefer(inner_, p))>;
        return BasicCallerRunsExecutor<Result>(boost::asio::prefer(inner_, p));
    }

    template <class Function>
    void execute(Function&& f) const {
        if (detail::caller_runs_armed() && boost::asio::query(inner_, boost::asio::execution::blocking) !=
                                               boost::asio::execution::blocking.never) {
            detail::caller_runs_armed() = false;
            std::forward<Function>(f)();
            return;
        }
        inner_.execute(std::forward<Function>(f));
    }

    friend bool operator==(const BasicCallerRunsExecutor& a, const BasicCallerRunsExecutor& b) noexcept {
        return a.inner_ == b.inner_;
    }
    friend bool operator!=(const BasicCallerRunsExecutor& a, const BasicCallerRunsExecutor& b) noexcept {
        return !(a == b);
    }

    const inner_type& inner() const noexcept { return inner_; }

private:
    inner_type inner_;
};

/// Over an io_context's executor: what the client uses (server/client/client.hpp, ClientStrand).
using CallerRunsExecutor = BasicCallerRunsExecutor<boost::asio::io_context::executor_type>;

}  // namespace rr::server
