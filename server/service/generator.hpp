// The service side of a generator function (robdef `{generator}` return and/or last parameter;
// wire.md §6.7 "generator function"). A generator function handler returns a Generator; the
// ObjectService gives it an `index` (random int32 ≥ 0, unique in the service) and drives it with the
// client's GeneratorNextReq entries (1123 → 1124):
//   * Next: `parameter` present for parameter generators; the reply carries `return` (int32 0 for a
//     void return); an error ends the generator (StopIteration 109 is the normal end);
//   * Close: a GeneratorNextReq carrying Error 109 → close(), answered with `return` int32 0;
//   * Abort: a GeneratorNextReq carrying Error 107 → abort(), answered the same way.
// After an error from next() the index is released: a later Next gets InvalidOperation ("Invalid
// generator"), as CORE answers an unknown index. After close or abort the index stays known for 30 s
// (CORE keeps the generator as long): the next Next is answered StopIteration (after a close) or
// OperationAborted (after an abort), as official clients expect, without calling next(); then the
// index goes. Generators of a client are dropped when its session ends, and after 10 minutes without
// a request (CORE's generator idle timeout).
//
// Threads: next/close/abort run on the requesting client's strand (one client at a time: a
// generator belongs to the session that created it). They must not block; async_next may complete
// later from any thread, and then overlapping calls are the generator's business.
#pragma once

#include <functional>
#include <optional>

#include "base/error/rr_error.hpp"
#include "core/value/value.hpp"

namespace rr::server {

/// Completes a request with a value (Null for void) or an error; call once, from any thread.
using Completion = std::function<void(Result<Value>)>;

class Generator {
public:
    virtual ~Generator() = default;

    /// The next value. `parameter` holds the client's value for parameter generators (checked against
    /// the robdef), nullopt otherwise. Return Null for a void-return generator; return StopIteration
    /// (MessageErrorType::StopIteration) when done. Default: StopIteration.
    virtual Result<Value> next(std::optional<Value> parameter);
    /// Asynchronous form; the default calls next() and completes at once.
    virtual void async_next(std::optional<Value> parameter, Completion done);
    /// The client closed the generator early (or finished a parameter generator). Default: nothing.
    virtual Result<void> close() { return {}; }
    /// The client aborted the generator. Default: nothing.
    virtual Result<void> abort() { return {}; }
};

/// A Generator made of functions, for simple cases: `next` is required, `close`/`abort` optional.
class FunctionGenerator : public Generator {
public:
    using NextFn = std::function<Result<Value>(std::optional<Value>)>;
    using EndFn = std::function<Result<void>()>;
    explicit FunctionGenerator(NextFn next, EndFn close = {}, EndFn abort = {})
        : next_(std::move(next)), close_(std::move(close)), abort_(std::move(abort)) {}
    Result<Value> next(std::optional<Value> parameter) override { return next_(std::move(parameter)); }
    Result<void> close() override { return close_ ? close_() : Result<void>(); }
    Result<void> abort() override { return abort_ ? abort_() : Result<void>(); }

private:
    NextFn next_;
    EndFn close_, abort_;
};

}  // namespace rr::server
