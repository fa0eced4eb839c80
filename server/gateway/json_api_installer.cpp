#include "server/gateway/json_api_installer.hpp"

#include "server/gateway/auth/http_auth.hpp"
#include "server/gateway/json_api.hpp"
#include "server/gateway/json_rest.hpp"
#include "server/gateway/json_socket.hpp"

namespace rr::server::gateway {

std::shared_ptr<JsonApi> install_json_api(http::HttpServer& http, const std::vector<std::shared_ptr<DeviceMirror>>& devices,
                                          std::shared_ptr<auth::GatewayAuth> auth) {
    auto api = std::make_shared<JsonApi>(devices);
    if (auth) {
        auth::install_login_routes(http, auth);
        api->set_auth(std::move(auth));
    }
    install_json_rest(http, api);
    install_json_socket(http, api);
    return api;
}

}  // namespace rr::server::gateway
