#include "server/gateway/rate_window.hpp"

#include <cmath>
#include <sstream>

namespace rr::server::gateway {

RatePeriod rate_period(double hz) {
    RatePeriod r;
    if (!std::isfinite(hz) || hz < kMinRateHz || hz > kMaxRateHz) {
        std::ostringstream s;
        s << "\"max_rate_hz\" must be a number from " << kMinRateHz << " to " << kMaxRateHz;
        r.error = s.str();
        return r;
    }
    r.period = RateClock(static_cast<std::int64_t>(std::llround(1e9 / hz)));
    return r;
}

}  // namespace rr::server::gateway
