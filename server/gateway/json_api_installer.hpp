// The JSON API of docs/json-api.md on an HTTP server: REST routes under /api/devices and the
// `rr-gateway.json.v1` WebSocket, over the gateway's devices.
#pragma once

#include <memory>
#include <vector>

#include "server/gateway/device_mirror.hpp"
#include "server/http/http_server.hpp"

namespace rr::server::gateway {

class JsonApi;
namespace auth {
class GatewayAuth;
}

/// Installs the JSON API and returns it (the gateway adds discovered devices to it).
/// `auth` (optional): the gateway's users and permissions — adds /api/login, /api/logout, /api/whoami
/// and checks every request (docs/security.md).
std::shared_ptr<JsonApi> install_json_api(http::HttpServer& http, const std::vector<std::shared_ptr<DeviceMirror>>& devices,
                                          std::shared_ptr<auth::GatewayAuth> auth = nullptr);

}  // namespace rr::server::gateway
