// The demo device `create`: a simulated iRobot Create served as `experimental.create.Create`
// (robdef/builtin/experimental_create.hpp), on top of CreateSimulation (create_sim.hpp: units, room,
// walls, Drive semantics).
//
// Members:
//   Drive(velocity, radius)   sets the drive command (mm/s, mm; constants DRIVE_STRAIGHT, SPIN_*).
//                             Out-of-range values: InvalidArgument.
//   DistanceTraveled          int32, mm since start (rounded), signed            [readonly]
//   AngleTraveled             int32, degrees since start (rounded), counter-clockwise positive [readonly]
//   Bumpers                   uint8, bit 0 right, bit 1 left; set while touching a wall [readonly]
//   Bump()                    event, fired to every client each time the robot hits a wall
//   StartStreaming()          the calling client session starts streaming: the `packets` wire gets a
//                             SensorPacket every packet_period (20 Hz) while at least one session
//                             streams, and the service calls `play_callback` on the most recent
//                             streaming client (the paper's pattern: the robot asks its client what to
//                             play) on every bump and every play_period (5 s); a bump during an
//                             outstanding call is played right after that call returns
//   StopStreaming()           the calling session stops streaming (a session that closes stops too)
//   packets                   wire SensorPacket [readonly]; holds the last packet sent (one is set at
//                             start, so PeekInValue always answers; the copy sent with a WireConnectRet
//                             is dropped by the official client, as with CORE's WireBroadcaster)
//   play_callback(DistanceTraveled, AngleTraveled) → uint8[]
//                             the reply is kept as the robot's "song" (Create OI song bytes: note,
//                             duration pairs); its length and first byte travel in the packets. At most
//                             one call is outstanding; a failed call is counted and skipped.
//
// SensorPacket: ID = 19 (the Create Open Interface's stream header byte); Data = kSensorDataSize bytes,
// little-endian:
//   offset size  field
//    0     u8    layout version (1)
//    1     u8    bumpers (bit 0 right, bit 1 left)
//    2     u16   packet sequence number (counts from 1, wraps)
//    4     i32   DistanceTraveled, mm
//    8     i32   AngleTraveled, degrees
//   12     i32   x, mm (room centre = 0, +x = the robot's initial heading)
//   16     i32   y, mm (+y = to the robot's initial left)
//   20     i32   heading, 0.01 degree, 0 … 35999, counter-clockwise from +x
//   24     i16   commanded velocity, mm/s (0 after a bump)
//   26     i16   commanded radius, mm
//   28     u32   simulated time, ms since start
//   32     u16   wall hits since start (wraps)
//   34     u8    length of the last play_callback reply (saturates at 255; 0 = none yet)
//   35     u8    first byte of the last play_callback reply (0 = none)
//
// Time: advance(dt) moves the simulation in fixed steps of step_period (50 Hz) and does the streaming
// work; start() drives it in real time (PeriodicTask on an io_context); tests call advance()
// with simulated time instead.
//
// Threads: every public function is thread-safe (one mutex guards the state; events, wire values and
// callbacks are sent after it is released). Member handlers hold only a weak reference to the device.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include <boost/asio/io_context.hpp>

#include "server/demo/create_sim.hpp"
#include "server/demo/periodic_task.hpp"
#include "server/service/callback_member.hpp"
#include "server/service/service_object.hpp"
#include "server/service/wire_member.hpp"

namespace rr::server::demo {

struct CreateDeviceOptions {
    CreateGeometry geometry;
    std::chrono::milliseconds step_period{20};    ///< simulation step (50 Hz)
    std::chrono::milliseconds packet_period{50};  ///< SensorPacket rate while streaming (20 Hz)
    std::chrono::milliseconds play_period{5000};  ///< play_callback while streaming; 0 = only on bumps
};

inline constexpr std::uint8_t kSensorPacketId = 19;
inline constexpr std::size_t kSensorDataSize = 36;

/// The play_callback bookkeeping.
struct PlayStats {
    std::uint32_t calls = 0, replies = 0, errors = 0;
    std::vector<std::uint8_t> last_song;  ///< the last reply (at most kMaxSongBytes kept)
};
inline constexpr std::size_t kMaxSongBytes = 256;

/// The Data bytes of a SensorPacket (layout above).
std::array<std::uint8_t, kSensorDataSize> encode_sensor_data(const CreateState& state, std::uint16_t sequence,
                                                             const std::vector<std::uint8_t>& last_song,
                                                             bool have_song);

class CreateDevice : public std::enable_shared_from_this<CreateDevice> {
public:
    /// A device with its ServiceObject (experimental.create.Create) and handlers attached; not
    /// advancing until start() or advance(). Errors: the definition or handler setup failed.
    static Result<std::shared_ptr<CreateDevice>> create(CreateDeviceOptions options = {});
    ~CreateDevice();
    CreateDevice(const CreateDevice&) = delete;
    CreateDevice& operator=(const CreateDevice&) = delete;

    /// The root object to serve (ObjectService::create("create", object())).
    const std::shared_ptr<ServiceObject>& object() const noexcept { return object_; }
    const CreateDeviceOptions& options() const noexcept { return options_; }

    // What the member handlers do (also usable directly).
    Result<void> drive(std::int16_t velocity, std::int16_t radius);
    void start_streaming(const SessionRef& session);
    void stop_streaming(const SessionRef& session);
    /// Places the robot (pose in mm and degrees; clamped into the room). Totals are kept.
    void place(double x_mm, double y_mm, double heading_deg);

    CreateState state() const;
    /// Whether a live session is streaming.
    bool streaming() const;
    PlayStats play_stats() const;
    /// Sequence number of the last SensorPacket sent (0 before the first).
    std::uint16_t packet_sequence() const;
    /// The current SensorPacket value (not sent).
    Value sensor_packet() const;

    /// Advances the simulation by `dt` (fixed steps; remainders carry over; at most 1 s at once) and
    /// sends what is due: Bump events, a packet, a play_callback call.
    void advance(std::chrono::nanoseconds dt);

    /// Advances in real time on `io` (every step_period, PeriodicTask). Call once.
    void start(boost::asio::io_context& io);
    /// Stops the timer (pending work is cancelled). Idempotent.
    void stop();

private:
    explicit CreateDevice(CreateDeviceOptions options);
    Result<void> attach_handlers();
    Value make_packet_locked(std::uint16_t sequence) const;
    void call_play(const SessionRef& target, std::int32_t distance, std::int32_t angle);

    const CreateDeviceOptions options_;
    std::shared_ptr<ServiceObject> object_;
    std::shared_ptr<WireMember> packets_;
    std::shared_ptr<CallbackMember> play_callback_;

    mutable std::mutex mutex_;
    CreateSimulation sim_;
    std::chrono::nanoseconds pending_{0}, packet_due_{0}, play_due_{0};
    std::vector<SessionRef> streamers_;  // in StartStreaming order; the last one gets play_callback
    std::uint16_t sequence_ = 0;
    PlayStats play_stats_;
    bool play_outstanding_ = false;
    bool bump_play_pending_ = false;  // a bump came while a call was outstanding

    std::shared_ptr<PeriodicTask> driver_;  // real time (start())
};

}  // namespace rr::server::demo
