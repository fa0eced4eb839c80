// One recording (docs/recording.md): the members of one gateway device written to MCAP files.
//
// The live path only hands over what it already has: each wire value and event is the SharedEntry the
// gateway fans out to its clients (DeviceMirror::subscribe; the reference, not a copy), each pipe packet
// the element the gateway's own pipe endpoint received (its bytes shared), each polled property the
// device's reply. They wait in a RecordQueue (record_queue.hpp: bounded by RecordingSpec::queue_bytes;
// when it is full the entry is dropped and counted, the live path never waits, allocates nothing per
// value once warm and does not wake the writer per value) and one writer thread per recording (named
// "rr-record"; the property poller "rr-record-poll") hands them to each format the spec enables
// (recording_format.hpp; built in: `robotraconteur`, the entry's bytes in RR message format 4, cached and
// shared with the native clients' sends; `json`, the JSON API's mapping; `foxglove_image`) and writes
// what they make with McapWriter (core/mcap), rotating files by size, time and the size of the index the
// writer keeps for the file's summary, deleting the oldest files over the disk budget. Every file holds
// the device's service definitions, then each format's schemas and channels.
//
// Where: below a RecordingsRoot (recordings_root.hpp), in the spec's sub-folder, each file made new with
// O_EXCL|O_NOFOLLOW (a name taken, e.g. by a recording of the same prefix started in the same second,
// gets a `-2`, `-3`… before `.mcap`). The writer thread does all of the disk work, the first file
// included: start() only checks the spec and starts it; the start's outcome is told to
// RecordingListeners::started.
//
// Times: log_time = the gateway's receive time (system clock, ns since the Unix epoch); publish_time =
// the device's own time stamp where the value carries one (a wire value's `packettime`), else log_time.
//
// Failure: an I/O error (an unwritable directory, a full disk, the recordings root's budget used up)
// ends the recording in state `failed` with the error (status(), RecordingListeners::ended); the file
// written so far keeps its complete chunks. The gateway goes on serving.
//
// Lifetime: the writer thread keeps its Recording alive until it has ended (stopped or failed); the
// last reference may go with it.
//
// Thread-safe. stop() may be called from any thread, including the device's strand.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "server/gateway/device_mirror.hpp"
#include "server/gateway/json_api.hpp"
#include "server/gateway/shared_entry.hpp"
#include "server/record/record_queue.hpp"
#include "server/record/recording_format.hpp"
#include "server/record/recording_spec.hpp"
#include "server/record/recordings_root.hpp"

namespace rr::server::record {

enum class RecordingState : std::uint8_t { recording, stopping, stopped, failed };
std::string_view recording_state_name(RecordingState s) noexcept;

struct RecordingStatus {
    std::uint64_t id = 0;
    RecordingSpec spec;
    RecordingState state = RecordingState::recording;
    std::string error;                 ///< why it failed ("" otherwise)
    std::vector<std::string> files;    ///< this recording's files still on disk (full paths), oldest first
    std::uint64_t bytes = 0;           ///< their size now
    std::uint64_t messages = 0;        ///< messages written (all channels, all files)
    std::uint64_t drops = 0;           ///< entries dropped because the queue was full
    std::uint64_t queued_bytes = 0;    ///< waiting for the writer now
    double duration_s = 0;             ///< since start (until the end, once ended)
    std::vector<std::string> members;  ///< the members recorded
    /// Recorded wires, pipes and events whose connection the device has not answered yet: their values
    /// are recorded from the answer on (0 once each is connected, or refused; properties are polled).
    std::size_t connecting = 0;
};
/// {"id", "device", "state", "error"?, "files", "bytes", "messages", "drops", "queued_bytes",
///  "duration_s", "connecting", "members", "spec"} (docs/recording.md "JSON API").
nlohmann::json status_json(const RecordingStatus& s);

class Recording;

/// What a recording tells its owner, each from the writer thread.
struct RecordingListeners {
    /// Once: the first file is open and the members subscribed (ok), or the start failed (the error;
    /// the recording has then ended, `failed`, and `ended` is not called). `recording.status()` and
    /// `recording.shared_from_this()` may be called.
    std::function<void(Recording& recording, const Result<void>& started)> started;
    /// Once, when a recording that started has ended (stopped or failed): its final status.
    std::function<void(const RecordingStatus&)> ended;
};

class Recording : public std::enable_shared_from_this<Recording> {
public:
    /// Checks the spec against `spec.device` (`device`, connected: its definitions are needed) and starts
    /// the writer thread, which is admitted by `root`'s budget, opens the sub-folder `spec.directory` and
    /// the first file, subscribes the members, then tells `listeners.started`. `spec.members` names root
    /// members (`packets`) or members below the root by path (`Webcams[0].FrameStream`, object_path.hpp);
    /// empty: every wire, pipe and event of the root. Errors here: InvalidArgument (a member the root
    /// object, or the object at the path, does not have; a path that does not follow objrefs,
    /// object_path.hpp; a member of a kind that cannot be recorded: functions, callbacks, objrefs,
    /// memories; a bad directory or prefix; an encoding none of `formats` is), InvalidState (device not
    /// connected). Errors told to `started`: OutOfSystemResource (the root's budget,
    /// RecordingsRoot::admit), IOError (a folder or file that cannot be made; the message names the path
    /// and the reason). `formats`: those the spec may enable, in the order their channels are added.
    static Result<std::shared_ptr<Recording>> create(std::uint64_t id, RecordingSpec spec, std::shared_ptr<gateway::DeviceMirror> device,
                                                     std::shared_ptr<gateway::JsonApi> api, std::shared_ptr<RecordingsRoot> root,
                                                     RecordingListeners listeners = {},
                                                     const RecordingFormats& formats = builtin_recording_formats());
    /// create(), then waits for the start's outcome: every error above is returned (`rr record`, tests).
    static Result<std::shared_ptr<Recording>> start(std::uint64_t id, RecordingSpec spec, std::shared_ptr<gateway::DeviceMirror> device,
                                                    std::shared_ptr<gateway::JsonApi> api, std::shared_ptr<RecordingsRoot> root,
                                                    const RecordingFormats& formats = builtin_recording_formats());
    ~Recording();

    /// Stops taking entries, writes what is queued, closes the file (summary and index); `done` (may be
    /// empty) is called from the writer thread once the file is closed, or at once when already ended.
    void stop(std::function<void(const RecordingStatus&)> done = {});
    /// Blocks until the writer thread has ended (after stop() or a failure).
    void wait();
    RecordingStatus status() const;
    std::uint64_t id() const noexcept { return id_; }

private:
    using Item = RecordQueue::Item;
    struct File;

    Recording(std::uint64_t id, RecordingSpec spec, std::shared_ptr<gateway::DeviceMirror> device,
              std::shared_ptr<gateway::JsonApi> api, std::shared_ptr<RecordingsRoot> root, std::vector<RecordedMember> members,
              std::vector<std::string> definition_names, const RecordingFormats& formats);
    /// From the live path: queue (the reference) or drop.
    void offer(std::uint16_t member, gateway::SharedEntryPtr entry);
    /// A wire's value: not recorded when it arrived before the newest one recorded (RecordQueue::offer_newest).
    void offer_wire(std::uint16_t member, gateway::SharedEntryPtr entry);
    /// The open file's size into files_ and the root's budget (once per batch: the writer does not take
    /// mutex_ per item). False: the root's budget is used up.
    bool note_file_size();
    RRError root_full() const;
    void subscribe_members();
    /// The device answered one member's connection (wire, pipe) or subscription (event).
    void member_answered();
    void unsubscribe_members();
    void poll_loop();
    void writer_loop();
    /// The writer's first steps: admission, folder, first file, subscriptions, poller.
    Result<void> begin();
    /// Ends the recording `failed` with `error` (listeners told); `started_ok`: whether it had started.
    void end_failed(const RRError& error, bool started_ok);
    Result<void> open_file();
    Result<void> write_item(const Item& item);
    Result<void> close_file();
    void enforce_budget();

    const std::uint64_t id_;
    const RecordingSpec spec_;
    const std::shared_ptr<gateway::DeviceMirror> device_;
    const std::shared_ptr<gateway::JsonApi> api_;
    const std::shared_ptr<RecordingsRoot> root_;
    const std::vector<RecordedMember> members_;
    /// The service name each of the device's definition texts declares (DeviceTypes::texts order).
    const std::vector<std::string> definition_names_;
    const FormatContext format_context_{spec_, members_, *api_};
    /// The enabled formats' encoders, in the formats' order (writer thread only).
    std::vector<std::unique_ptr<FormatEncoder>> encoders_;
    const std::chrono::steady_clock::time_point started_ = std::chrono::steady_clock::now();
    RecordingListeners listeners_;

    mutable std::mutex mutex_;
    std::condition_variable poll_wake_;  // the property poller's
    bool stopping_ = false;
    RecordingState state_ = RecordingState::recording;
    std::string error_;
    std::chrono::steady_clock::time_point ended_;
    std::vector<std::function<void(const RecordingStatus&)>> stop_listeners_;
    struct FileEntry {
        std::string name;    // in folder_
        std::string path;    // shown (folder_->path_of(name))
        std::uint64_t size;  // the open one's: updated as written
    };
    std::vector<FileEntry> files_;
    std::atomic<std::uint64_t> messages_{0};
    RecordQueue queue_;  // its own lock: the live path never takes mutex_

    // Subscriptions (guarded by mutex_).
    std::vector<std::uint64_t> subscriptions_;  // DeviceMirror::subscribe ids
    std::vector<std::uint64_t> pipes_;          // shared_endpoints pipe ids
    std::size_t connecting_ = 0;                // members not answered yet (RecordingStatus::connecting)

    // Writer thread only.
    std::unique_ptr<File> file_;
    std::unique_ptr<RecordingsFolder> folder_;
    std::shared_ptr<RecordingsRoot::Admission> admission_;
    std::uint64_t noted_bytes_ = 0;  // what the admission was told the files hold
    std::vector<std::uint32_t> sequence_;  // per encoder and member: encoders_ index * members + member
    std::uint64_t file_counter_ = 0;
    std::thread poller_;  // started and joined by the writer thread

    std::thread writer_;
};

}  // namespace rr::server::record
