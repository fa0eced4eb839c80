// CompletionGuard: a completion that is called exactly once even when the work carrying it is dropped.
//
// PumpHandle::dispatch drops work once the connection's pump has closed. A completion travelling in
// such work would then never be called, and its caller would wait for nothing (or, through the
// gateway, answer "request was not answered"). Held by a shared_ptr in the dispatched work, the guard
// answers ConnectionError when it is destroyed uncalled.
#pragma once

#include <functional>
#include <utility>

#include "core/error/rr_error.hpp"

namespace rr::server {

template <class T>
class CompletionGuard {
public:
    using Handler = std::function<void(Result<T>)>;

    explicit CompletionGuard(Handler done) : done_(std::move(done)) {}
    CompletionGuard(const CompletionGuard&) = delete;
    CompletionGuard& operator=(const CompletionGuard&) = delete;
    ~CompletionGuard() {
        if (done_) done_(fail(MessageErrorType::ConnectionError, "client connection closed"));
    }

    /// Calls the completion (the first call only).
    void operator()(Result<T> r) {
        if (auto d = std::exchange(done_, nullptr)) d(std::move(r));
    }
    /// Takes the completion out, to hand it on; the guard then answers nothing.
    Handler take() { return std::exchange(done_, nullptr); }

private:
    Handler done_;
};

}  // namespace rr::server
