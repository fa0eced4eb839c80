// An executor over another (an io_context's, type-erased) that lets a thread about to block run a
// strand's work itself instead of waking a worker thread for it.
//
// A blocking client call hands its request to the connection's strand and waits for the reply. With a
// plain strand, the hand-over from a foreign thread is a post: a worker thread wakes only to encode
// the request and write it, and the caller wakes again for the reply (two cross-thread wake-ups per
// call, issue 14). A strand built over this executor (`asio::make_strand(CallerRunsExecutor(ex))`)
// runs the caller's function on the caller's own thread when, inside a CallerRunsScope, the caller
// dispatches to the strand and the strand is idle; the reply is then the call's one wake-up. The
// strand's guarantees hold: the function runs only while the strand is held by this thread, and work
// queued meanwhile is posted to the worker threads as usual (never-blocking execution).
// Outside a scope, or when the strand is busy, everything behaves as the inner executor does.
#pragma once

#include <concepts>
#include <type_traits>
#include <utility>

#include <boost/asio/any_io_executor.hpp>
#include <boost/asio/execution.hpp>
#include <boost/asio/prefer.hpp>
#include <boost/asio/query.hpp>
#include <boost/asio/require.hpp>

namespace rr::server {

class CallerRunsExecutor {
public:
    using inner_type = boost::asio::any_io_executor;

    // Constrained, not a plain converting constructor: checking whether this type is copyable must
    // not ask whether it converts to any_io_executor, which asks whether it is an executor (clang
    // reports the recursion as an error).
    template <class Inner>
        requires(!std::same_as<std::decay_t<Inner>, CallerRunsExecutor> && std::constructible_from<inner_type, Inner>)
    explicit CallerRunsExecutor(Inner&& inner) noexcept : inner_(std::forward<Inner>(inner)) {}

    /// While alive, the next possibly-blocking execute() of a CallerRunsExecutor on this thread runs
    /// the function inline (once: the scope is used up by it, so work the function starts is not
    /// also pulled onto this thread). Scopes do not nest.
    class Scope {
    public:
        Scope() noexcept { armed() = true; }
        ~Scope() { armed() = false; }
        Scope(const Scope&) = delete;
        Scope& operator=(const Scope&) = delete;
        /// True when the function ran inline on this thread.
        bool used() const noexcept { return !armed(); }
    };

    template <class Property>
        requires boost::asio::can_query<const inner_type&, Property>::value
    decltype(auto) query(const Property& p) const {
        return boost::asio::query(inner_, p);
    }
    template <class Property>
        requires boost::asio::can_require<const inner_type&, Property>::value
    CallerRunsExecutor require(const Property& p) const {
        return CallerRunsExecutor(boost::asio::require(inner_, p));
    }
    template <class Property>
        requires boost::asio::can_prefer<const inner_type&, Property>::value
    CallerRunsExecutor prefer(const Property& p) const {
        return CallerRunsExecutor(boost::asio::prefer(inner_, p));
    }

    template <class Function>
    void execute(Function&& f) const {
        if (armed() && boost::asio::query(inner_, boost::asio::execution::blocking) !=
                           boost::asio::execution::blocking.never) {
            armed() = false;
            std::forward<Function>(f)();
            return;
        }
        inner_.execute(std::forward<Function>(f));
    }

    friend bool operator==(const CallerRunsExecutor& a, const CallerRunsExecutor& b) noexcept {
        return a.inner_ == b.inner_;
    }
    friend bool operator!=(const CallerRunsExecutor& a, const CallerRunsExecutor& b) noexcept { return !(a == b); }

    const inner_type& inner() const noexcept { return inner_; }

private:
    static bool& armed() noexcept {
        thread_local bool flag = false;
        return flag;
    }

    inner_type inner_;
};

}  // namespace rr::server
