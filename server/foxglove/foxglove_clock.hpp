// The time a Foxglove client sees (docs/foxglove.md "Time"): the serverInfo capability `time`, `time`
// messages, and the receive times of messageData, from a device's clock when one is chosen.
//
// A clock is a readable wire of the root object of type com.robotraconteur.device.clock.DeviceTime (the
// standard DeviceClock's `device_clock_now`; its `device_utc` is read) or
// com.robotraconteur.datetime.DateTimeUTC. Which device: the one `foxglove.clock` names, else a
// connected device whose root object is the standard clock (com.robotraconteur.datetime.clock.Clock).
// Cameras and robots have a DeviceClock too; they are used only when named (which clock a lab means is
// theirs to say, and a clock that ticks only while a camera streams would stall Foxglove's time).
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "server/foxglove/foxglove_channels.hpp"

namespace rr::server::foxglove {

enum class ClockWireKind { device_time, date_time_utc };

/// Whether `member` is a clock wire (see above) and of which kind; nothing for anything else.
std::optional<ClockWireKind> clock_wire_kind(const LiveMember& member);
/// The clock wire among a device's members (its root object's; a DeviceTime wire before a
/// DateTimeUTC one), or nothing.
const LiveMember* find_clock_wire(const std::vector<LiveMember>& members);
/// Whether the device's root object is the standard clock device (com.robotraconteur.datetime.clock.Clock).
bool is_clock_device(const gateway::DeviceMirror& device);

/// The time of one WirePacket of a clock wire in ns since the Unix epoch; nothing when the value is
/// null, malformed, or before the epoch (a device clock without UTC leaves `device_utc` zero).
std::optional<std::uint64_t> clock_time_ns(const gateway::JsonApi& api, const LiveMember& member, ClockWireKind kind,
                                           const MessageEntry& packet);

/// The gateway's clock source: subscribes to one device's clock wire while that device is connected
/// and hands its times on. Thread-safe.
class FoxgloveClock : public std::enable_shared_from_this<FoxgloveClock> {
public:
    /// `on_time` is called when a new clock time arrived (now_ns() reads it), at most once per `interval`;
    /// called without locks held, on the device's strand.
    FoxgloveClock(std::shared_ptr<gateway::JsonApi> api, std::chrono::milliseconds interval,
                  std::function<void()> on_time);
    ~FoxgloveClock();

    /// Follows `member` (a clock wire of a connected device), replacing the clock followed before.
    void follow(const LiveMember& member, ClockWireKind kind);
    /// The device went away: its clock is no longer followed.
    void device_gone(const std::string& device);
    /// The device followed now ("" = none).
    std::string device() const;
    /// Whether a clock time arrived (from any device followed so far).
    bool has_time() const;
    /// A receive time: the newest clock time plus the wall time elapsed since it arrived, never less
    /// than a time returned before; the wall clock while no clock time arrived.
    std::uint64_t now_ns();

private:
    void on_packet(std::uint64_t serial, const gateway::SharedEntryPtr& e);
    void stop_locked(std::vector<std::pair<std::shared_ptr<gateway::DeviceMirror>, std::uint64_t>>& to_unsubscribe);

    std::shared_ptr<gateway::JsonApi> api_;
    const std::chrono::milliseconds interval_;
    std::function<void()> on_time_;
    mutable std::mutex mutex_;
    std::shared_ptr<const LiveMember> member_;
    ClockWireKind kind_ = ClockWireKind::device_time;
    std::uint64_t serial_ = 0, upstream_ = 0;
    bool upstream_known_ = false;
    std::optional<std::uint64_t> last_time_;  // the newest clock time
    std::chrono::steady_clock::time_point last_arrival_{}, last_forwarded_{};
    std::uint64_t last_returned_ = 0;
};

}  // namespace rr::server::foxglove
