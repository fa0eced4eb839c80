// The REST half of the JSON API (docs/json-api.md §REST): routes under /api/devices on the gateway's
// HttpServer, each answered with JSON (`application/json`), errors as {"error": {"name", "message"}}
// with the HTTP status of json_api_error.hpp.
//
//   GET  /api/devices                               device list
//   GET  /api/devices/{name}                        status + definitions + root members
//   GET  /api/devices/{name}/definitions            definition texts
//   GET  /api/devices/{name}/access                 what the caller's roles allow on each root member (json_access.hpp)
//   GET  /api/devices/{name}/properties/{member}    {"value": …}
//   PUT  /api/devices/{name}/properties/{member}    body {"value": …} → {}
//   POST /api/devices/{name}/functions/{member}     body {"args": […] | {…}, "max_items"?: n} → {"return": …} | {"items": […]}
//   GET  /api/devices/{name}/wires/{member}         {"value": …, "time": {…}}
// Query parameters: `object` (relative service path of an object below the root), `max_items`;
// /access takes `members` and `device_user`.
// Request bodies are bounded by HttpOptions::max_body_bytes (413 beyond, by the HttpServer).
#pragma once

#include <memory>

#include "server/gateway/json_api.hpp"
#include "server/http/http_server.hpp"

namespace rr::server::gateway {

/// Adds the /api routes to `http` (before the server accepts connections).
void install_json_rest(http::HttpServer& http, std::shared_ptr<JsonApi> api);

/// Percent-decoding of a URL path segment or query value (`+` is a space in query values).
/// Errors: InvalidArgument for a malformed escape.
Result<std::string> url_decode(std::string_view text, bool plus_is_space);

}  // namespace rr::server::gateway
