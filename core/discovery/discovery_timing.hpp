// When a node sends discovery datagrams (official CORE TcpTransport.cpp IPNodeDiscovery; wire.md §11.1),
// as two sans-IO schedules fed with the time and random numbers:
//
//   AnnounceSchedule   first announce 500 ms after start, then every period (55 s for TCP discovery;
//                      at least 500 ms); a received request or a changed ServiceStateNonce pulls the
//                      next announce in to at most 500 ms from now.
//   RequestSchedule    a round of 3 requests: the first 250–1000 ms after the trigger, the others
//                      900–1500 ms apart; if another trigger came within the last second of a round's
//                      end, one more round starts 5 s later.
//
// Usage: call due(now) when the deadline passes; it says whether to send now and moves the deadline.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>

namespace rr::discovery {

using MonoTime = std::chrono::steady_clock::time_point;

inline constexpr std::chrono::milliseconds kDefaultAnnouncePeriod{55000};
inline constexpr std::chrono::milliseconds kMinAnnouncePeriod{500};
inline constexpr std::chrono::milliseconds kAnnounceSoon{500};

class AnnounceSchedule {
public:
    /// Starts announcing: the first announce is due 500 ms from `now`. Period below 500 ms becomes 500 ms.
    void start(MonoTime now, std::chrono::milliseconds period = kDefaultAnnouncePeriod);
    void stop() noexcept { next_.reset(); }
    bool running() const noexcept { return next_.has_value(); }
    /// A request arrived or our nonce changed: announce within 500 ms (never later than already planned).
    void announce_soon(MonoTime now);
    /// True when an announce is to be sent now; the next one is then planned one period later.
    bool due(MonoTime now);
    std::optional<MonoTime> next_deadline() const noexcept { return next_; }
    std::chrono::milliseconds period() const noexcept { return period_; }

private:
    std::optional<MonoTime> next_;
    std::chrono::milliseconds period_ = kDefaultAnnouncePeriod;
};

class RequestSchedule {
public:
    /// Asks for requests now (start of listening, `rr discover`, a subscription): starts a round of 3
    /// unless one is running; `random` spreads the first send over 250–1000 ms.
    void trigger(MonoTime now, std::uint32_t random);
    void stop() noexcept {
        next_.reset();
        remaining_ = 0;
    }
    /// True when a request is to be sent now; plans the next one (`random` for the 900–1500 ms gap).
    bool due(MonoTime now, std::uint32_t random);
    std::optional<MonoTime> next_deadline() const noexcept { return next_; }

private:
    std::optional<MonoTime> next_;
    int remaining_ = 0;
    std::optional<MonoTime> last_trigger_;
};

}  // namespace rr::discovery
