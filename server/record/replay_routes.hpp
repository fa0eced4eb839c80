// The JSON API's routes for replayed devices (docs/recording.md "Replay"):
//   GET  /api/replays          {"replays": [replay_status_json…]}
//   GET  /api/replays/{name}   replay_status_json
//   POST /api/replays/{name}   body {"position_s"?: s, "speed"?: x, "loop"?: bool, "state"?: "playing"|"paused"}
//                              (applied in that order) → replay_status_json
// Errors: 404 unknown replay, 400 bad body (unknown keys, bad values). With logins on: 401 without one,
// and controls (POST) need the `write` permission on the device (403).
#pragma once

#include <memory>
#include <vector>

#include "server/gateway/json_api.hpp"
#include "server/http/http_server.hpp"
#include "server/record/replay_device.hpp"

namespace rr::server::record {

void install_replay_routes(http::HttpServer& http, std::shared_ptr<gateway::JsonApi> api,
                           std::vector<std::shared_ptr<ReplayDevice>> replays);

/// Applies a control body to `device`. Errors: InvalidArgument naming the key.
Result<void> apply_replay_control(ReplayDevice& device, const nlohmann::json& body);

}  // namespace rr::server::record
