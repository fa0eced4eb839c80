// api_installer() for rr-gateway (server/app/gateway_extensions.hpp): the JSON API of
// docs/json-api.md — REST routes under /api/devices and the `rr-gateway.json.v1` WebSocket.
#include "server/app/gateway_extensions.hpp"
#include "server/gateway/json_api.hpp"
#include "server/gateway/json_rest.hpp"
#include "server/gateway/json_socket.hpp"

namespace rr::server::app {

ApiInstaller api_installer() {
    return [](http::HttpServer& http, const std::vector<std::shared_ptr<gateway::DeviceMirror>>& devices) {
        auto api = std::make_shared<gateway::JsonApi>(devices);
        gateway::install_json_rest(http, api);
        gateway::install_json_socket(http, api);
    };
}

}  // namespace rr::server::app
