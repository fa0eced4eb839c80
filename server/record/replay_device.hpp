// A device whose source is a recording (docs/recording.md "Replay"): the recorded service definition
// served by an ObjectService, its wires, pipes and events played from the file's `robotraconteur`
// channels (those of the format that replays: recording_format.hpp) with the recorded spacing (divided by the speed factor; looping if asked), its recorded
// properties answering their last value at the replay position, its functions refused with a clear
// error (InvalidOperation "… is a recording …"), writes refused (ReadOnlyMember).
//
// The gateway serves it like a live device: the ObjectService is registered on a node of the gateway's
// own and mirrored like any device (so native clients, the JSON API and the dashboard see it alike);
// play, pause, seek and speed come from the JSON API (replay_routes.hpp).
//
// Objects below the root are served when members of theirs were recorded (channels with a `path`): the
// objrefs on the way answer them, and refuse other indexes with ObjectNotFound "… was not recorded".
// Values are sent with the replay's wall clock as their wire time stamp (the recorded device time
// stays in the file's publish_time).
//
// Threads: one playback thread per device; every public function is thread-safe.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "base/error/rr_error.hpp"
#include "core/value/value.hpp"
#include "server/record/channel_metadata.hpp"
#include "server/service/object_service.hpp"

namespace rr::server::record {

class RecordingFormat;

struct ReplayOptions {
    std::string file;
    std::string name;      ///< the device's name ("" = the recorded device's)
    double speed = 1.0;    ///< > 0
    bool loop = false;
    bool paused = false;
    /// The most memory the file's reader holds at once (mcap::ReaderLimits::max_memory_bytes; the
    /// gateway's recordings.replay_memory_bytes): a file that needs more is refused at open or fails.
    std::uint64_t memory_bytes = 256ull << 20;
    /// Told (from the playback thread) when playing fails: the device's name and the error (the state is
    /// then "failed"; the gateway logs it).
    std::function<void(const std::string& device, const std::string& error)> on_error;
};

struct ReplayStatus {
    std::string name, file, recorded_device, object_type;
    std::string state;             ///< "playing", "paused", "ended", "failed"
    std::string error;
    double position_s = 0;         ///< replay position, seconds from the recording's first message
    double duration_s = 0;         ///< first to last message, seconds
    std::uint64_t start_ns = 0;    ///< log_time of the first message (ns since the Unix epoch)
    double speed = 1.0;
    bool loop = false;
    std::uint64_t played = 0;      ///< messages played since start
    std::vector<std::string> members;
};
/// {"name", "file", "recorded_device", "object_type", "state", "error"?, "position_s", "duration_s",
///  "start_ns", "speed", "loop", "played", "members"}.
nlohmann::json replay_status_json(const ReplayStatus& s);

class ReplayDevice : public std::enable_shared_from_this<ReplayDevice> {
public:
    /// Opens and checks the file and builds the service (not playing yet: start()). Errors, each naming
    /// the file: IOError (unreadable), DataSerializationError / BufferLimitViolation (not an MCAP file, or
    /// corrupt: the reader's message with the record and offset), InvalidArgument (no `robotraconteur`
    /// channel, one whose entry_format is missing or unknown, no service definition, definitions that do
    /// not parse, a member the definition lacks).
    static Result<std::shared_ptr<ReplayDevice>> open(ReplayOptions options);
    ~ReplayDevice();

    const std::string& name() const noexcept { return name_; }
    const std::shared_ptr<ObjectService>& service() const noexcept { return service_; }

    /// Starts the playback thread (paused when ReplayOptions::paused).
    void start();
    /// Ends the playback thread.
    void stop();

    void play();
    void pause();
    /// Moves to `seconds` after the first message (clamped to the recording): wires hold their last value
    /// at that point, properties answer theirs, and playing goes on from there.
    /// Errors: InvalidArgument (negative or not finite).
    Result<void> seek(double seconds);
    /// Errors: InvalidArgument (not above 0, or over 1000).
    Result<void> set_speed(double speed);
    void set_loop(bool loop);
    ReplayStatus status() const;

private:
    struct Channel {
        RecordedKind kind = RecordedKind::wire;
        const RecordingFormat* format = nullptr;  ///< reads its messages back (RecordingFormat::read_entry)
        const robdef::MemberDefinition* member = nullptr;
        std::string path;         ///< the object's path below the root ("" = the root)
        ServiceObject* object = nullptr;  ///< the served object at `path` (owned by objects_)
        std::string context;      ///< the service defining the object (for unqualified type names)
        std::string property_key; ///< key of properties_: path + '\n' + member
    };
    struct Playback;

    ReplayDevice() = default;
    void run();
    /// Applies one recorded message (`live`: sent to clients; else only the state is updated).
    void apply(std::uint16_t channel, std::span<const std::byte> data, bool live);
    /// Rebuilds the state at `t_ns` (last wire and property values at or before it).
    void restore_state(std::uint64_t t_ns);

    ReplayOptions options_;
    std::string name_, recorded_device_, object_type_, context_service_;
    std::shared_ptr<const ServiceTypes> types_;
    std::shared_ptr<ServiceObject> root_;
    /// Every served object by its path below the root ("" = root_), the recorded ones and those on
    /// the way to them (docs/recording.md "Objects below the root").
    std::map<std::string, std::shared_ptr<ServiceObject>> objects_;
    /// Creates the object at `path` of `type` and those on the way, with their objref resolvers.
    Result<ServiceObject*> object_at(const std::string& path, const std::string& type);
    /// Functions refused, properties answering their recorded value.
    void serve_members(ServiceObject& object, const std::string& path);
    std::shared_ptr<ObjectService> service_;
    std::map<std::uint16_t, Channel> channels_;  // robotraconteur channels by id
    std::uint64_t start_ns_ = 0, end_ns_ = 0;

    mutable std::mutex mutex_;
    std::condition_variable wake_;
    bool playing_ = true, stop_ = false, ended_ = false, loop_ = false;
    double speed_ = 1.0;
    std::optional<std::uint64_t> seek_to_;  // file time, ns
    std::uint64_t position_ns_ = 0;         // file time of the last message played
    std::chrono::steady_clock::time_point anchor_steady_;
    std::uint64_t anchor_file_ns_ = 0;
    std::string error_;
    std::map<std::string, Value> properties_;  // last value at the position, by Channel::property_key
    std::atomic<std::uint64_t> played_{0};
    std::unique_ptr<Playback> playback_;
    std::thread thread_;
};

}  // namespace rr::server::record
