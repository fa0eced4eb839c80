// Logins of browsers and scripts to the gateway's JSON API (`auth: gateway`; docs/security.md
// "Browsers: login page, cookie, tokens"):
//
//   POST /api/login    body {"username", "password"} or {"token"} → {"user", "roles", "via"} and a
//                      session cookie `rrgw_session` (HttpOnly, SameSite=Strict, Path=/, Max-Age =
//                      session_ttl; Secure when the request came over TLS). 401 wrong credentials,
//                      429 (Retry-After) while the client's address is locked out.
//   POST /api/logout   ends the cookie's session, clears the cookie → {}
//   GET  /api/whoami   {"auth": true, "user", "roles", "via"}; 401 when not logged in; {"auth": false}
//                      when the gateway has no users (the dashboard then shows no login).
//
// Every other JSON API request is authenticated by `Authorization: Bearer <token or JWT>` or by the
// session cookie (authenticate_request): 401 (with WWW-Authenticate: Bearer) without either.
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <variant>

#include "server/gateway/auth/gateway_auth.hpp"
#include "server/gateway/json_api_error.hpp"
#include "server/http/http_server.hpp"

namespace rr::server::gateway::auth {

inline constexpr std::string_view kSessionCookie = "rrgw_session";

/// The value of cookie `name` in a Cookie header ("" when absent).
std::string cookie_value(std::string_view cookie_header, std::string_view name);

/// Who sent `request`: a principal, or 401 / 429.
std::variant<PrincipalPtr, ApiError> authenticate_request(GatewayAuth& auth, const http::Request& request);

/// An ApiError for a failed login: 429 when rate limited, else 401 AuthenticationError.
ApiError login_error(const RRError& error);

/// `{"user", "roles", "via"}`.
nlohmann::json principal_json(const Principal& who);

/// Adds /api/login, /api/logout and /api/whoami (before install_json_rest's catch-all /api routes
/// would answer them; method-specific routes are tried first).
void install_login_routes(http::HttpServer& http, std::shared_ptr<GatewayAuth> auth);

}  // namespace rr::server::gateway::auth
