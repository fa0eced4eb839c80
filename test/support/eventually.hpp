// Polling for the threaded tests: wait until a condition holds, with a bound, instead of sleeping a
// fixed time (which is either too short on a loaded machine or wastes time on a quiet one).
//
// The bound is only there so that a hang ends: it is never the expected duration. CI runs 8 tests at
// once on 2 vCPUs beside sanitizer builds (load ~15), so the default is generous (30 s); a caller that
// waits for something slower (a child process starting under ASan) passes a longer one. A condition
// that holds at once costs nothing.
#pragma once

#include <chrono>
#include <thread>

namespace rr::testing {

/// The default bound of eventually(): a bound on a hang, not a duration to expect.
inline constexpr std::chrono::milliseconds kHangBound = std::chrono::seconds(30);

/// Calls `pred` every `step` until it returns true or `limit` has passed; the last call's answer.
template <class Pred>
bool eventually(Pred&& pred, std::chrono::milliseconds limit = kHangBound,
                std::chrono::milliseconds step = std::chrono::milliseconds(10)) {
    const auto end = std::chrono::steady_clock::now() + limit;
    while (std::chrono::steady_clock::now() < end) {
        if (pred()) return true;
        std::this_thread::sleep_for(step);
    }
    return pred();
}

}  // namespace rr::testing
