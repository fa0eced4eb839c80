#include "server/gateway/auth/gateway_auth.hpp"

#include <algorithm>

#include <openssl/crypto.h>
#include <openssl/rand.h>

#include "core/session/elements.hpp"

namespace rr::server::gateway::auth {

namespace {

bool configures_logins(const GatewayAuthSettings& s) {
    return !s.users.empty() || (s.tokens && !s.tokens->empty()) || s.jwt.has_value();
}

}  // namespace

std::shared_ptr<const GatewayAuth::Credentials> GatewayAuth::make_credentials(GatewayAuthSettings& s) {
    auto c = std::make_shared<Credentials>();
    c->users = std::move(s.users);
    c->tokens = std::move(s.tokens);
    c->jwt = std::move(s.jwt);
    c->policy = s.policy ? std::move(s.policy) : std::make_shared<AccessPolicy>();
    for (const auto& u : c->users.users()) {
        Principal p;
        p.name = u.username;
        p.roles = u.privileges;
        p.via = "password";
        c->user_principals[u.username] = with_policy(std::move(p), *c);
    }
    s.users = PasswordTable{};
    s.tokens.reset();
    s.jwt.reset();
    return c;
}

GatewayAuth::GatewayAuth(GatewayAuthSettings settings)
    : settings_(std::move(settings)), limiter_(settings_.limits) {
    enabled_ = configures_logins(settings_);
    credentials_.store(make_credentials(settings_));
}

PrincipalPtr GatewayAuth::with_policy(Principal p, const Credentials& c) {
    p.policy = c.policy;
    return std::make_shared<const Principal>(std::move(p));
}

CredentialSummary GatewayAuth::summary() const {
    auto c = credentials();
    CredentialSummary out;
    out.users = c->users.users().size();
    out.tokens = c->tokens ? c->tokens->size() : 0;
    out.jwt_algorithm = c->jwt ? c->jwt->settings().algorithm : "";
    out.roles = c->policy->role_names().size();
    return out;
}

std::string describe(const CredentialSummary& s) {
    std::string out = std::to_string(s.users) + " user(s)";
    if (s.tokens) out += ", " + std::to_string(s.tokens) + " token(s)";
    if (!s.jwt_algorithm.empty()) out += ", JWT " + s.jwt_algorithm;
    return out + ", " + std::to_string(s.roles) + " role(s)";
}

Result<void> GatewayAuth::reload(GatewayAuthSettings fresh) {
    if (!configures_logins(fresh))
        return fail(MessageErrorType::InvalidConfiguration,
                    "the reloaded gateway.auth has no users, tokens or JWT key: logins stay on with the previous "
                    "ones (restart the gateway to turn logins off)");
    auto next = make_credentials(fresh);
    std::lock_guard lock(mutex_);
    credentials_.store(next);
    for (auto it = sessions_.begin(); it != sessions_.end();) {
        auto& who = it->second.who;
        auto user = who->via == "password" ? next->user_principals.find(who->name) : next->user_principals.end();
        if (user == next->user_principals.end()) {
            it = sessions_.erase(it);
        } else {
            who = user->second;
            ++it;
        }
    }
    web_principals_.clear();
    return {};
}

Result<void> GatewayAuth::check_limit(const std::string& address) {
    if (auto wait = limiter_.blocked_for(address, settings_.steady_now()); wait > 0) {
        counters_.rate_limited.fetch_add(1);
        return fail(MessageErrorType::AuthenticationError,
                    "Too many failed logins from this address; try again in " + std::to_string(wait) + " s");
    }
    return {};
}

void GatewayAuth::record_failure(const std::string& address, LoginChannel channel) {
    switch (channel) {
        case LoginChannel::rr: counters_.failed_rr.fetch_add(1); break;
        case LoginChannel::http: counters_.failed_http.fetch_add(1); break;
        case LoginChannel::token: counters_.failed_token.fetch_add(1); break;
        case LoginChannel::websocket: counters_.failed_websocket.fetch_add(1); break;
    }
    if (limiter_.failed(address, settings_.steady_now())) counters_.lockouts.fetch_add(1);
}

Result<PrincipalPtr> GatewayAuth::login_rr(std::string_view username, const MessageElement* credentials,
                                           std::string_view peer) {
    const MessageElement* token = nullptr;
    if (credentials && credentials->type == DataTypes::dictionary_t) token = credentials->find("token");
    if (token && token->type == DataTypes::string_t) return login_rr_token(username, read_string(*token), peer);
    const std::string address = address_of(peer);
    if (auto ok = check_limit(address); !ok) return ok.take_error();
    if (auto ok = this->credentials()->users.check(username, credentials); !ok) {
        record_failure(address, LoginChannel::rr);
        return ok.take_error();
    }
    auto who = principal_for_user(username);
    if (!who) return fail(MessageErrorType::AuthenticationError, "Invalid username or password");
    limiter_.succeeded(address);
    counters_.succeeded.fetch_add(1);
    return who;
}

Result<PrincipalPtr> GatewayAuth::login_rr_token(std::string_view username, std::string_view token, std::string_view peer) {
    auto who = login_token(token, peer, LoginChannel::rr);
    if (!who) return who.take_error();
    // The session's user name says where its roles come from, so a token never takes a password user's.
    const std::string name = (*who)->rr_user_name();
    if (username != name)
        return fail(MessageErrorType::AuthenticationError, "this token logs in as user \"" + name + "\"; connect with that username");
    remember_token_user(name, *who);
    return who;
}

void GatewayAuth::remember_token_user(const std::string& name, PrincipalPtr who) {
    std::lock_guard lock(mutex_);
    if (web_principals_.size() >= settings_.max_sessions && !web_principals_.count(name)) web_principals_.clear();  // bounded
    web_principals_[name] = std::move(who);
}

Result<PrincipalPtr> GatewayAuth::login_password(std::string_view username, std::string_view password,
                                                 std::string_view peer, LoginChannel channel) {
    const std::string address = address_of(peer);
    if (auto ok = check_limit(address); !ok) return ok.take_error();
    const std::string digest = PasswordTable::md5_hex(password);
    auto c = credentials();
    bool ok = false;
    for (const auto& u : c->users.users())
        ok |= (u.username == username) &
              (u.password_md5.size() == digest.size() &&
               CRYPTO_memcmp(u.password_md5.data(), digest.data(), digest.size()) == 0);
    auto who = ok ? c->user_principals.find(username)->second : nullptr;
    if (!who) {
        record_failure(address, channel);
        return fail(MessageErrorType::AuthenticationError, "Invalid username or password");
    }
    limiter_.succeeded(address);
    counters_.succeeded.fetch_add(1);
    return who;
}

Result<PrincipalPtr> GatewayAuth::login_token(std::string_view token, std::string_view peer, LoginChannel channel,
                                              std::string* reason) {
    const std::string address = address_of(peer);
    if (auto ok = check_limit(address); !ok) return ok.take_error();
    std::string why = "no token authentication configured";
    auto c = credentials();
    if (c->tokens) {
        if (auto p = c->tokens->check(token)) {
            limiter_.succeeded(address);
            counters_.succeeded.fetch_add(1);
            return with_policy(std::move(*p), *c);
        } else {
            why = p.error().message;
        }
    }
    if (c->jwt && looks_like_jwt(token)) {
        if (auto p = c->jwt->verify(token, settings_.unix_now())) {
            limiter_.succeeded(address);
            counters_.succeeded.fetch_add(1);
            return with_policy(std::move(*p), *c);
        } else {
            why = "JWT: " + p.error().message;
        }
    }
    if (reason) *reason = why;
    record_failure(address, channel);
    return fail(MessageErrorType::AuthenticationError, "Invalid token");
}

PrincipalPtr GatewayAuth::principal_for_user(std::string_view username) const {
    auto c = credentials();
    auto it = c->user_principals.find(username);
    if (it != c->user_principals.end()) return it->second;
    std::lock_guard lock(mutex_);
    auto w = web_principals_.find(username);
    return w == web_principals_.end() ? nullptr : w->second;
}

Result<std::string> GatewayAuth::web_rr_user(std::string_view cookie_header) {
    // The cookie's name and value: as http_auth.hpp's cookie_value (kept here, below the HTTP layer).
    std::string id;
    while (!cookie_header.empty()) {
        auto semi = cookie_header.find(';');
        auto pair = cookie_header.substr(0, semi);
        cookie_header = semi == std::string_view::npos ? std::string_view{} : cookie_header.substr(semi + 1);
        while (!pair.empty() && pair.front() == ' ') pair.remove_prefix(1);
        constexpr std::string_view kName = "rrgw_session=";
        if (pair.substr(0, kName.size()) == kName) id = std::string(pair.substr(kName.size()));
    }
    auto who = id.empty() ? nullptr : session(id);
    if (!who) return fail(MessageErrorType::AuthenticationError, "Username not provided");
    if (who->via == "password") return who->name;
    std::string name = who->rr_user_name();
    remember_token_user(name, who);
    return name;
}

std::string GatewayAuth::open_session(PrincipalPtr who) {
    unsigned char raw[32];
    if (RAND_bytes(raw, sizeof raw) != 1) return {};
    static constexpr char kHex[] = "0123456789abcdef";
    std::string id;
    for (unsigned char c : raw) {
        id += kHex[c >> 4];
        id += kHex[c & 15];
    }
    const auto now = settings_.steady_now();
    std::lock_guard lock(mutex_);
    std::erase_if(sessions_, [&](const auto& kv) { return kv.second.expires <= now; });
    if (sessions_.size() >= settings_.max_sessions) {
        auto oldest = std::min_element(sessions_.begin(), sessions_.end(),
                                       [](const auto& a, const auto& b) { return a.second.expires < b.second.expires; });
        sessions_.erase(oldest);
    }
    sessions_[id] = Session{std::move(who), now + settings_.session_ttl};
    return id;
}

PrincipalPtr GatewayAuth::session(std::string_view id) const {
    std::lock_guard lock(mutex_);
    auto it = sessions_.find(id);
    if (it == sessions_.end() || it->second.expires <= settings_.steady_now()) return nullptr;
    return it->second.who;
}

void GatewayAuth::close_session(std::string_view id) {
    std::lock_guard lock(mutex_);
    if (auto it = sessions_.find(id); it != sessions_.end()) sessions_.erase(it);
}

}  // namespace rr::server::gateway::auth
