// CompletionGuard: a completion that is called exactly once even when the work carrying it is dropped.
//
// PumpHandle::post and dispatch destroy work unrun once the connection's pump has closed (as Asio
// destroys an uninvoked handler). A completion travelling in such work would then never be called,
// and its caller would wait for nothing (or, through the gateway, answer "request was not answered").
// Held by a shared_ptr in the posted work, the guard answers ConnectionError when it is destroyed
// uncalled. Used by the client (typed and raw) and by the service side's callback requests.
#pragma once

#include <functional>
#include <utility>

#include "base/error/rr_error.hpp"

namespace rr::server {

template <class T>
class CompletionGuard {
public:
    using Handler = std::function<void(Result<T>)>;

    /// `closed_message`: the ConnectionError's message when the guard answers; a string literal
    /// (static storage: no copy per guard, one guard per request).
    explicit CompletionGuard(Handler done, const char* closed_message = "client connection closed")
        : done_(std::move(done)), closed_message_(closed_message) {}
    CompletionGuard(const CompletionGuard&) = delete;
    CompletionGuard& operator=(const CompletionGuard&) = delete;
    ~CompletionGuard() {
        if (auto d = std::exchange(done_, nullptr)) d(fail(MessageErrorType::ConnectionError, closed_message_));
    }

    /// Calls the completion (the first call only).
    void operator()(Result<T> r) {
        if (auto d = std::exchange(done_, nullptr)) d(std::move(r));
    }
    /// Takes the completion out, to hand it on; the guard then answers nothing.
    Handler take() { return std::exchange(done_, nullptr); }

private:
    Handler done_;
    const char* closed_message_;
};

}  // namespace rr::server
