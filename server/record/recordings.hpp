// The gateway's recordings (docs/recording.md): started from the configuration's `record:` entries
// (each once its device is connected) or from the JSON API, listed with their state, sizes, drops and
// errors, stopped on request or when the gateway stops. Thread-safe.
#pragma once

#include <cstdint>
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

namespace rr::server::record {

class Recordings : public std::enable_shared_from_this<Recordings> {
public:
    /// `on_event` hears every start, stop and failure (the gateway logs them): `status`, and `what`
    /// ("started", "stopped", "failed").
    using EventListener = std::function<void(const RecordingStatus& status, std::string_view what)>;
    Recordings(std::shared_ptr<gateway::JsonApi> api, EventListener on_event = {});
    ~Recordings();

    /// Starts a recording now. Errors (as ApiError, the JSON API's status): 404 unknown device, 503 not
    /// connected, 400 bad members, 507 IOError (directory or file not writable; the failed recording is
    /// listed with its error too).
    std::variant<RecordingStatus, gateway::ApiError> start(RecordingSpec spec);
    /// A `record:` entry: starts when its device is (or becomes) connected; a failure is listed and told.
    void start_when_connected(RecordingSpec spec);
    /// Stops recording `id`; `done` gets its final status once its file is closed (nullopt: unknown id).
    void stop(std::uint64_t id, std::function<void(std::optional<RecordingStatus>)> done);
    std::vector<RecordingStatus> list() const;
    std::optional<RecordingStatus> get(std::uint64_t id) const;
    /// Stops every recording and waits for their files to be closed (the gateway's shutdown).
    void stop_all();

private:
    struct Entry {
        std::shared_ptr<Recording> recording;
        std::optional<RecordingStatus> failed;  ///< a start that failed
    };
    std::uint64_t failed_start(RecordingSpec spec, const RRError& error);

    std::shared_ptr<gateway::JsonApi> api_;
    EventListener on_event_;
    mutable std::mutex mutex_;
    std::map<std::uint64_t, Entry> entries_;
    std::uint64_t next_id_ = 1;
    std::vector<std::pair<std::shared_ptr<gateway::DeviceMirror>, std::uint64_t>> listeners_;
    bool stopped_ = false;
};

/// The JSON API's routes for recordings (docs/recording.md "JSON API"):
///   GET  /api/recordings             {"recordings": [status…]}
///   POST /api/recordings             body: a spec (spec_from_json) → 201 status
///   GET  /api/recordings/{id}        status
///   POST /api/recordings/{id}/stop   status once the file is closed
/// With logins on, every route needs a login (401).
void install_recording_routes(http::HttpServer& http, std::shared_ptr<gateway::JsonApi> api,
                              std::shared_ptr<Recordings> recordings);

}  // namespace rr::server::record
