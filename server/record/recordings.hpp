// The gateway's recordings (docs/recording.md): started from the configuration's `record:` entries
// (each once its device is connected) or from the JSON API, listed with their state, sizes, drops and
// errors, stopped on request or when the gateway stops. All of them write below one RecordingsRoot
// (recordings_root.hpp) and keep to RecordingsSettings: at most `max_active` at once, `queue_bytes` at
// most `max_queue_bytes`, the root's disk budget, and the statuses of the last `keep_ended` ended ones
// (an ended recording keeps only its status: its threads, queue and buffers are gone). Thread-safe.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <variant>
#include <vector>

#include "server/gateway/json_api.hpp"
#include "server/http/http_server.hpp"
#include "server/record/recording.hpp"
#include "server/record/recordings_root.hpp"

namespace rr::server::record {

class Recordings : public std::enable_shared_from_this<Recordings> {
public:
    /// `on_event` hears every start, stop and failure (the gateway logs them): `status`, and `what`
    /// ("started", "stopped", "failed"; "refused" for a start the root's budget or max_active refused,
    /// with the reason in status.error).
    using EventListener = std::function<void(const RecordingStatus& status, std::string_view what)>;
    /// `settings.root` "" is resolved with default_recordings_root($STATE_DIRECTORY).
    Recordings(std::shared_ptr<gateway::JsonApi> api, RecordingsSettings settings, EventListener on_event = {});
    ~Recordings();

    using StartDone = std::function<void(std::variant<RecordingStatus, gateway::ApiError>)>;
    /// Starts a recording; `done` gets its status once the first file is open (from the recording's
    /// writer thread), or the error (errors found at once: from this thread). Errors (as ApiError, the
    /// JSON API's status): 400 bad members, directory, prefix or queue_bytes over max_queue_bytes, 404
    /// unknown device, 429 max_active recordings running or starting, 503 not connected or the gateway
    /// stopping, 507 the root's budget (not listed) or a folder or file that cannot be made (listed as
    /// failed with the reason).
    void start(RecordingSpec spec, StartDone done);
    /// A `record:` entry: starts when its device is (or becomes) connected; a failure is listed and told.
    void start_when_connected(RecordingSpec spec);
    /// Stops recording `id`; `done` gets its final status once its file is closed (nullopt: unknown id).
    void stop(std::uint64_t id, std::function<void(std::optional<RecordingStatus>)> done);
    std::vector<RecordingStatus> list() const;
    std::optional<RecordingStatus> get(std::uint64_t id) const;
    /// Stops every recording and waits for their files to be closed (the gateway's shutdown).
    void stop_all();

    const std::shared_ptr<RecordingsRoot>& root() const noexcept { return root_; }
    const RecordingsSettings& settings() const noexcept { return settings_; }
    /// Recordings running or starting now.
    std::size_t active() const;

private:
    struct Entry {
        std::shared_ptr<Recording> recording;   ///< while it runs
        std::optional<RecordingStatus> ended;   ///< once it has ended (or a start that failed)
    };
    void start_impl(RecordingSpec spec, bool from_config, StartDone done);
    /// Lists a start that failed as an ended recording.
    std::uint64_t failed_start(RecordingSpec spec, const RRError& error);
    /// A recording ended: only its status stays, the oldest ended ones over keep_ended go.
    void ended(const RecordingStatus& status);
    void keep_ended_locked(std::uint64_t id);
    std::size_t active_locked() const;

    std::shared_ptr<gateway::JsonApi> api_;
    const RecordingsSettings settings_;
    const std::shared_ptr<RecordingsRoot> root_;
    EventListener on_event_;
    mutable std::mutex mutex_;
    std::map<std::uint64_t, Entry> entries_;
    std::deque<std::uint64_t> ended_order_;  // ids of ended entries, oldest first
    std::map<std::uint64_t, std::shared_ptr<Recording>> starting_;  // admitted to max_active, not yet started
    std::uint64_t next_id_ = 1;
    std::vector<std::pair<std::shared_ptr<gateway::DeviceMirror>, std::uint64_t>> listeners_;
    bool stopped_ = false;
};

/// The JSON API's routes for recordings (docs/recording.md "JSON API"):
///   GET  /api/recordings             {"recordings": [status…]}
///   POST /api/recordings             body: a spec (spec_from_json) → 201 status
///   GET  /api/recordings/{id}        status
///   POST /api/recordings/{id}/stop   status once the file is closed
/// With logins on, every route needs a login (401); starting and stopping need the `record` right on
/// the device (403), and a status shows its files, directory, prefix and error only to a login with
/// that right (others see the recording without them).
void install_recording_routes(http::HttpServer& http, std::shared_ptr<gateway::JsonApi> api,
                              std::shared_ptr<Recordings> recordings);

/// A status without what names places on the gateway's disk (files, spec.directory, spec.prefix, the
/// error's text): for a login without the `record` right on the recording's device.
nlohmann::json status_json_without_paths(const RecordingStatus& status);

}  // namespace rr::server::record
