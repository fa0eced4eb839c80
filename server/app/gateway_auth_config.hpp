// gateway.auth → the gateway's users, tokens, JWT key and policy (server/gateway/auth/), read from
// their files as the gateway starts and as `rr-gateway --check` checks them.
#pragma once

#include <memory>
#include <optional>

#include "base/error/rr_error.hpp"
#include "server/app/gateway_config.hpp"
#include "server/gateway/auth/gateway_auth.hpp"

namespace rr::server::app {

/// nullptr when gateway.auth configures no users, tokens or JWT (logins off). Errors:
/// InvalidConfiguration naming the key and the file ("gateway.auth.users: /etc/…: line 3: …").
Result<std::shared_ptr<gateway::auth::GatewayAuth>> load_gateway_auth(const GatewayAuthConfig& config);

/// The settings load_gateway_auth builds from, for GatewayAuth::reload (SIGHUP); nullopt when logins
/// are off. Errors: as load_gateway_auth.
Result<std::optional<gateway::auth::GatewayAuthSettings>> load_gateway_auth_settings(const GatewayAuthConfig& config);

}  // namespace rr::server::app
