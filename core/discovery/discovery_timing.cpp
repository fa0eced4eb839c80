#include "core/discovery/discovery_timing.hpp"

#include "core/discovery/node_table.hpp"

namespace rr::discovery {

void AnnounceSchedule::start(MonoTime now, std::chrono::milliseconds period) {
    period_ = period < kMinAnnouncePeriod ? kMinAnnouncePeriod : period;
    next_ = now + kAnnounceSoon;
}

void AnnounceSchedule::announce_soon(MonoTime now) {
    if (!next_) return;
    if (*next_ > now + kAnnounceSoon) next_ = now + kAnnounceSoon;
}

bool AnnounceSchedule::due(MonoTime now) {
    if (!next_ || *next_ > now) return false;
    next_ = now + period_;
    return true;
}

void RequestSchedule::trigger(MonoTime now, std::uint32_t random) {
    last_trigger_ = now;
    if (next_) return;  // a round is running (or a follow-up round is planned)
    remaining_ = 3;
    next_ = now + jitter(random, 250, 1000);
}

bool RequestSchedule::due(MonoTime now, std::uint32_t random) {
    if (!next_ || *next_ > now) return false;
    if (remaining_ <= 0) remaining_ = 3;  // a follow-up round begins
    --remaining_;
    if (remaining_ > 0) {
        next_ = now + jitter(random, 900, 1500);
    } else if (last_trigger_ && *last_trigger_ + std::chrono::milliseconds(1000) > now) {
        next_ = now + std::chrono::seconds(5);  // triggered again near the end: one more round
        last_trigger_.reset();
    } else {
        next_.reset();
    }
    return true;
}

}  // namespace rr::discovery
