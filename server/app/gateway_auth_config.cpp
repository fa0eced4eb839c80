#include "server/app/gateway_auth_config.hpp"

#include <fstream>
#include <sstream>

namespace rr::server::app {

namespace ga = gateway::auth;

namespace {

Unexpected config_error(const std::string& key, const std::string& message) {
    return fail(MessageErrorType::InvalidConfiguration, key + ": " + message);
}

}  // namespace

Result<std::shared_ptr<ga::GatewayAuth>> load_gateway_auth(const GatewayAuthConfig& c) {
    auto s = load_gateway_auth_settings(c);
    if (!s) return s.take_error();
    if (!*s) return std::shared_ptr<ga::GatewayAuth>();
    return std::make_shared<ga::GatewayAuth>(std::move(**s));
}

Result<std::optional<ga::GatewayAuthSettings>> load_gateway_auth_settings(const GatewayAuthConfig& c) {
    if (!c.enabled()) return std::optional<ga::GatewayAuthSettings>();
    ga::GatewayAuthSettings s;
    if (!c.users.empty()) {
        auto users = PasswordTable::load_file(c.users);
        if (!users) return config_error("gateway.auth.users", users.error().message);
        if (users->empty()) return config_error("gateway.auth.users", c.users + ": no users in the file");
        s.users = std::move(*users);
    }
    if (!c.tokens.empty()) {
        auto tokens = ga::BearerTokens::load_file(c.tokens);
        if (!tokens) return config_error("gateway.auth.tokens", tokens.error().message);
        if (tokens->empty()) return config_error("gateway.auth.tokens", c.tokens + ": no tokens in the file");
        s.tokens = std::move(*tokens);
    }
    if (!c.jwt.algorithm.empty()) {
        std::ifstream in(c.jwt.key, std::ios::binary);
        if (!in) return config_error("gateway.auth.jwt.key", c.jwt.key + ": cannot read the key file");
        std::ostringstream text;
        text << in.rdbuf();
        ga::JwtSettings j;
        j.algorithm = c.jwt.algorithm;
        j.key = text.str();
        // An HS256 secret file usually ends with a newline that is not part of the secret.
        if (j.algorithm == "HS256")
            while (!j.key.empty() && (j.key.back() == '\n' || j.key.back() == '\r')) j.key.pop_back();
        j.audience = c.jwt.audience;
        j.issuer = c.jwt.issuer;
        j.user_claim = c.jwt.user_claim;
        j.roles_claim = c.jwt.roles_claim;
        j.leeway = std::chrono::seconds(c.jwt.leeway_s);
        auto v = ga::JwtVerifier::create(std::move(j));
        if (!v) return config_error("gateway.auth.jwt", c.jwt.key + ": " + v.error().message);
        s.jwt = std::move(*v);
    }
    auto policy = std::make_shared<ga::AccessPolicy>();
    for (const auto& [name, rules] : c.roles) {
        std::vector<ga::AccessRule> out;
        for (const auto& r : rules)
            out.push_back(ga::AccessRule{r.devices, r.members, r.read, r.write, r.call, r.lock, r.record});
        policy->add_role(name, std::move(out));
    }
    s.policy = std::move(policy);
    s.limits.max_failures = c.max_failures;
    s.limits.window = std::chrono::seconds(c.window_s);
    s.limits.lockout = std::chrono::seconds(c.lockout_s);
    s.session_ttl = std::chrono::seconds(c.session_ttl_s);
    return std::optional<ga::GatewayAuthSettings>(std::move(s));
}

}  // namespace rr::server::app
