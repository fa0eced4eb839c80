// Polling for the threaded tests: wait until a condition holds, with a bound, instead of sleeping a
// fixed time (which is either too short on a loaded machine or wastes time on a quiet one).
#pragma once

#include <chrono>
#include <thread>

namespace rr::testing {

/// Calls `pred` every `step` until it returns true or `limit` has passed; the last call's answer.
template <class Pred>
bool eventually(Pred&& pred, std::chrono::milliseconds limit = std::chrono::seconds(5),
                std::chrono::milliseconds step = std::chrono::milliseconds(10)) {
    const auto end = std::chrono::steady_clock::now() + limit;
    while (std::chrono::steady_clock::now() < end) {
        if (pred()) return true;
        std::this_thread::sleep_for(step);
    }
    return pred();
}

}  // namespace rr::testing
