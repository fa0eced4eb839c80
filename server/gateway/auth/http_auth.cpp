#include "server/gateway/auth/http_auth.hpp"

#include <algorithm>
#include <cctype>

#include <boost/beast/http.hpp>

#include "server/gateway/json_api.hpp"

namespace rr::server::gateway::auth {

namespace bhttp = boost::beast::http;

namespace {

std::string_view field(const http::Request& req, std::string_view name) {
    auto v = req[name];
    return {v.data(), v.size()};
}

std::string_view trim(std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
    return s;
}

http::Response json_reply(const http::Request& req, unsigned status, const nlohmann::json& body) {
    auto r = http::make_response(req, static_cast<bhttp::status>(status), json_text(body) + "\n", "application/json");
    r.set(bhttp::field::cache_control, "no-store");
    return r;
}

http::Response error_reply(const http::Request& req, const ApiError& e) {
    auto r = json_reply(req, e.status, nlohmann::json{{"error", error_object(e)}});
    if (e.status == 401) r.set(bhttp::field::www_authenticate, "Bearer");
    if (e.status == 429) {
        // "… try again in N s"
        auto p = e.message.rfind("in ");
        if (p != std::string::npos) r.set(bhttp::field::retry_after, e.message.substr(p + 3, e.message.find(' ', p + 3) - p - 3));
    }
    return r;
}

std::string session_cookie(const std::string& id, long max_age, bool secure) {
    std::string c = std::string(kSessionCookie) + "=" + id + "; Path=/; HttpOnly; SameSite=Strict; Max-Age=" + std::to_string(max_age);
    if (secure) c += "; Secure";
    return c;
}

}  // namespace

std::string cookie_value(std::string_view header, std::string_view name) {
    while (!header.empty()) {
        auto semi = header.find(';');
        auto pair = trim(header.substr(0, semi));
        header = semi == std::string_view::npos ? std::string_view{} : header.substr(semi + 1);
        auto eq = pair.find('=');
        if (eq == std::string_view::npos) continue;
        if (trim(pair.substr(0, eq)) == name) return std::string(trim(pair.substr(eq + 1)));
    }
    return {};
}

ApiError login_error(const RRError& error) {
    if (error.message.rfind("Too many failed logins", 0) == 0)
        return api_error(429, MessageErrorType::AuthenticationError, error.message);
    return api_error(401, MessageErrorType::AuthenticationError, error.message);
}

nlohmann::json principal_json(const Principal& who) {
    return nlohmann::json{{"user", who.name}, {"roles", who.roles}, {"via", who.via}};
}

std::variant<PrincipalPtr, ApiError> authenticate_request(GatewayAuth& auth, const http::Request& req) {
    const std::string_view peer = field(req, http::kClientAddressField);
    const std::string_view authorization = field(req, "Authorization");
    if (!authorization.empty()) {
        constexpr std::string_view kBearer = "Bearer ";
        if (authorization.size() <= kBearer.size() ||
            !std::equal(kBearer.begin(), kBearer.end(), authorization.begin(),
                        [](char a, char b) { return std::tolower(static_cast<unsigned char>(a)) == std::tolower(static_cast<unsigned char>(b)); }))
            return api_error(401, MessageErrorType::AuthenticationError, "only Authorization: Bearer is accepted");
        auto who = auth.login_token(trim(authorization.substr(kBearer.size())), peer, LoginChannel::token);
        if (!who) return login_error(who.error());
        return *who;
    }
    const std::string id = cookie_value(field(req, "Cookie"), kSessionCookie);
    if (!id.empty()) {
        if (auto who = auth.session(id)) return who;
        return api_error(401, MessageErrorType::AuthenticationError, "the session has expired or is unknown; log in again");
    }
    return api_error(401, MessageErrorType::AuthenticationError,
                     "login required (POST /api/login, an Authorization: Bearer token, or the dashboard's login page)");
}

void install_login_routes(http::HttpServer& http, std::shared_ptr<GatewayAuth> auth) {
    http.add_route(bhttp::verb::post, "/api/login", [auth](const http::Request& req, http::Responder respond) {
        if (!auth->enabled())
            return respond(error_reply(req, api_error(404, MessageErrorType::ResourceNotFound, "the gateway has no users (logins are off)")));
        auto body = parse_request_json(req.body());
        if (!body || !body->is_object())
            return respond(error_reply(req, api_error(400, MessageErrorType::InvalidArgument,
                                                      "the body must be {\"username\", \"password\"} or {\"token\"}")));
        const std::string_view peer = field(req, http::kClientAddressField);
        Result<PrincipalPtr> who = fail(MessageErrorType::AuthenticationError, "Invalid username or password");
        auto u = body->find("username");
        auto p = body->find("password");
        auto t = body->find("token");
        if (u != body->end() && u->is_string() && p != body->end() && p->is_string()) {
            who = auth->login_password(u->get<std::string>(), p->get<std::string>(), peer, LoginChannel::http);
        } else if (t != body->end() && t->is_string()) {
            who = auth->login_token(t->get<std::string>(), peer, LoginChannel::token);
        } else {
            return respond(error_reply(req, api_error(400, MessageErrorType::InvalidArgument,
                                                      "the body must be {\"username\", \"password\"} or {\"token\"}")));
        }
        if (!who) return respond(error_reply(req, login_error(who.error())));
        const std::string id = auth->open_session(*who);
        if (id.empty()) return respond(error_reply(req, api_error(500, MessageErrorType::InternalError, "no random session id")));
        auto r = json_reply(req, 200, principal_json(**who));
        r.set(bhttp::field::set_cookie,
              session_cookie(id, static_cast<long>(auth->settings().session_ttl.count()), field(req, http::kSecureField) == "1"));
        respond(std::move(r));
    });
    http.add_route(bhttp::verb::post, "/api/logout", [auth](const http::Request& req, http::Responder respond) {
        const std::string id = cookie_value(field(req, "Cookie"), kSessionCookie);
        if (!id.empty()) auth->close_session(id);
        auto r = json_reply(req, 200, nlohmann::json::object());
        r.set(bhttp::field::set_cookie, session_cookie("", 0, field(req, http::kSecureField) == "1"));
        respond(std::move(r));
    });
    http.add_route(bhttp::verb::get, "/api/whoami", [auth](const http::Request& req, http::Responder respond) {
        if (!auth->enabled()) return respond(json_reply(req, 200, nlohmann::json{{"auth", false}}));
        auto who = authenticate_request(*auth, req);
        if (auto* e = std::get_if<ApiError>(&who)) return respond(error_reply(req, *e));
        auto j = principal_json(*std::get<PrincipalPtr>(who));
        j["auth"] = true;
        respond(json_reply(req, 200, j));
    });
}

}  // namespace rr::server::gateway::auth
