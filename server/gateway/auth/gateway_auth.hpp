// The gateway's own logins (`auth: gateway`, docs/security.md "Gateway users and permissions"): its
// users (an official password file; the privileges column holds the user's roles), bearer tokens and
// JWTs for browsers, cookie sessions for the dashboard, failed-login rate limiting per client address,
// and the role → rule policy every check consults.
//
// Once any user, token or JWT key is configured (enabled()), every client of the gateway must log in
// and every member request is checked against the policy (deny by default). Native RR clients log in
// with a user of the password file (the same answers as our ObjectService gives: AuthenticationError
// "Invalid username or password", …) or with a bearer token or JWT in their credentials; browsers and scripts with a password (POST /api/login, cookie
// session), a bearer token or a JWT. Thread-safe.
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>

#include "base/error/rr_error.hpp"
#include "base/message/message.hpp"
#include "server/gateway/auth/access_policy.hpp"
#include "server/gateway/auth/login_limiter.hpp"
#include "server/gateway/auth/token_auth.hpp"
#include "server/service/password_table.hpp"

namespace rr::server::gateway::auth {

using PrincipalPtr = std::shared_ptr<const Principal>;

struct GatewayAuthSettings {
    PasswordTable users;
    std::optional<BearerTokens> tokens;
    std::optional<JwtVerifier> jwt;
    std::shared_ptr<const AccessPolicy> policy = std::make_shared<AccessPolicy>();
    LoginLimits limits;
    std::chrono::seconds session_ttl{8 * 3600};
    std::size_t max_sessions = 10000;
    /// Accept `?access_token=` on JSON WebSocket upgrades (off: a token in a URL ends up in logs).
    bool websocket_url_token = false;
    /// Clocks (tests replace them).
    std::function<std::chrono::steady_clock::time_point()> steady_now = [] { return std::chrono::steady_clock::now(); };
    std::function<std::int64_t()> unix_now = [] {
        return std::chrono::duration_cast<std::chrono::seconds>(std::chrono::system_clock::now().time_since_epoch()).count();
    };
};

/// Login counters for /metrics.
struct LoginCounters {
    std::atomic<std::uint64_t> succeeded{0};
    std::atomic<std::uint64_t> failed_rr{0}, failed_http{0}, failed_token{0}, failed_websocket{0};
    std::atomic<std::uint64_t> rate_limited{0};  ///< attempts refused because the address was locked out
    std::atomic<std::uint64_t> lockouts{0};      ///< addresses locked out
    std::atomic<std::uint64_t> denied{0};        ///< member requests refused by the policy
};

enum class LoginChannel { rr, http, token, websocket };

/// How many users, tokens and roles are in force, and the JWT algorithm ("" = none): for logs and --check.
struct CredentialSummary {
    std::size_t users = 0;
    std::size_t tokens = 0;
    std::string jwt_algorithm;
    std::size_t roles = 0;
};

/// "3 user(s), 2 token(s), JWT RS256, 4 role(s)" (tokens and JWT only when there are any).
std::string describe(const CredentialSummary& s);

class GatewayAuth {
public:
    explicit GatewayAuth(GatewayAuthSettings settings);

    /// Any user, token or JWT key configured: logins required, permissions checked.
    bool enabled() const noexcept { return enabled_; }
    bool has_users() const { return !credentials()->users.empty(); }
    /// The roles' rules in force (a reload swaps them; hold the pointer, not a reference into it).
    std::shared_ptr<const AccessPolicy> policy() const { return credentials()->policy; }
    /// The settings given at construction: limits, session lifetime, clocks. Users, tokens, JWT key and
    /// policy are in credentials() (they change on reload()).
    const GatewayAuthSettings& settings() const noexcept { return settings_; }
    CredentialSummary summary() const;

    /// Replaces the users, tokens, JWT key and roles' rules with `fresh`'s (SIGHUP, docs/security.md);
    /// its limits, session lifetime and clocks are ignored (those of the start stay). Logins in progress
    /// finish against the credentials they started with. Open cookie sessions of a password user get the
    /// user's new roles, or end when the user is gone; cookie sessions opened with a token or JWT end (a
    /// revoked token must not live on), and so do the roles of RR sessions those opened. An RR session of
    /// a password user is checked against the new roles from its next request on. Errors:
    /// InvalidConfiguration when `fresh` configures no user, token or key at all (turning logins off
    /// needs a restart, so that a truncated file cannot open the gateway to everyone).
    Result<void> reload(GatewayAuthSettings fresh);

    /// RR login (ConnectClientCombined / AuthenticateUser): `credentials` as the client sent it. A
    /// password user sends {"password": string}; a bearer token or JWT is sent as {"token": string}
    /// with the user name `<name>@token` / `<name>@jwt` (the token's name or the JWT's `sub`), the
    /// name its session then carries (as web_rr_user() gives out). Errors: AuthenticationError
    /// (PasswordTable's messages; "Invalid token"; "this token logs in as user \"…\"" for another
    /// user name; "Too many failed logins from this address; try again in N s" when the address is
    /// locked out).
    Result<PrincipalPtr> login_rr(std::string_view username, const MessageElement* credentials, std::string_view peer);
    /// Password login over HTTP / the JSON WebSocket. Errors: as login_rr ("Invalid username or password").
    Result<PrincipalPtr> login_password(std::string_view username, std::string_view password, std::string_view peer,
                                        LoginChannel channel);
    /// A bearer token or a JWT (`Authorization: Bearer …`, the WebSocket's first message). Errors:
    /// AuthenticationError "Invalid token" (the reason goes to `reason` for the log), or rate limited.
    Result<PrincipalPtr> login_token(std::string_view token, std::string_view peer, LoginChannel channel,
                                     std::string* reason = nullptr);

    /// The principal of an RR session whose user logged in as `username`: a user of the password file
    /// (its roles from there), or a name web_rr_user() gave out; nullptr when unknown.
    PrincipalPtr principal_for_user(std::string_view username) const;

    /// An RR session opened by a browser that logged in on the web page (its session cookie came with
    /// the rr+ws upgrade; `cookie_header` is that Cookie header): the RR user name of the session —
    /// the user's name for a password login, `<name>@token` / `<name>@jwt` for token and JWT logins
    /// (never a password user's name, so a token cannot borrow a user's roles). Errors:
    /// AuthenticationError when there is no valid session cookie.
    Result<std::string> web_rr_user(std::string_view cookie_header);

    /// Cookie sessions: a fresh random id (64 hex digits) for `who`, valid for session_ttl.
    std::string open_session(PrincipalPtr who);
    /// The session's principal, or nullptr (unknown or expired).
    PrincipalPtr session(std::string_view id) const;
    void close_session(std::string_view id);

    LoginCounters& counters() noexcept { return counters_; }
    const LoginCounters& counters() const noexcept { return counters_; }

private:
    /// What reload() replaces, swapped as a whole so that a check sees one consistent set.
    struct Credentials {
        PasswordTable users;
        std::optional<BearerTokens> tokens;
        std::optional<JwtVerifier> jwt;
        std::shared_ptr<const AccessPolicy> policy;
        std::map<std::string, PrincipalPtr, std::less<>> user_principals;
    };
    static std::shared_ptr<const Credentials> make_credentials(GatewayAuthSettings& s);
    std::shared_ptr<const Credentials> credentials() const { return credentials_.load(); }

    Result<void> check_limit(const std::string& address);
    void record_failure(const std::string& address, LoginChannel channel);
    static PrincipalPtr with_policy(Principal p, const Credentials& c);
    Result<PrincipalPtr> login_rr_token(std::string_view username, std::string_view token, std::string_view peer);
    /// Makes principal_for_user(name) answer `who` (an RR or web session of a token or JWT login).
    void remember_token_user(const std::string& name, PrincipalPtr who);

    GatewayAuthSettings settings_;  // users, tokens, jwt and policy moved out into credentials_
    std::atomic<std::shared_ptr<const Credentials>> credentials_;
    bool enabled_ = false;
    LoginLimiter limiter_;
    LoginCounters counters_;
    struct Session {
        PrincipalPtr who;
        std::chrono::steady_clock::time_point expires;
    };
    mutable std::mutex mutex_;
    std::map<std::string, Session, std::less<>> sessions_;
    std::map<std::string, PrincipalPtr, std::less<>> web_principals_;  // "<name>@<via>" → the newest such login
};

}  // namespace rr::server::gateway::auth
