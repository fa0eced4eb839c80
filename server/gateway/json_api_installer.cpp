#include "server/gateway/json_api_installer.hpp"

#include "server/gateway/json_api.hpp"
#include "server/gateway/json_rest.hpp"
#include "server/gateway/json_socket.hpp"

namespace rr::server::gateway {

std::shared_ptr<JsonApi> install_json_api(http::HttpServer& http, const std::vector<std::shared_ptr<DeviceMirror>>& devices) {
    auto api = std::make_shared<JsonApi>(devices);
    install_json_rest(http, api);
    install_json_socket(http, api);
    return api;
}

}  // namespace rr::server::gateway
