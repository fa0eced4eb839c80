// Browser credentials other than passwords (docs/security.md "Tokens and JWT"):
//
//  * BearerTokens: opaque tokens from a file, one per line: `<token> <name> <roles>` (roles
//    comma-separated, `_` for none; `#` lines and blank lines skipped). A token is at least 16
//    characters of [A-Za-z0-9._~+/=-]. Only SHA-256 digests of the tokens are kept in memory.
//  * JwtVerifier: JSON Web Tokens signed with HS256 (a shared secret), RS256 or ES256 (the issuer's
//    public key, PEM), verified with libjwt. The token's `alg` must be the configured one (no "none",
//    no algorithm switching); `exp` is required and `nbf` (when present) checked with a leeway; `aud`
//    (a string or an array) must contain the configured audience; `iss` must match when configured.
//    The user is the `user_claim` (default `sub`), the roles the `roles_claim` (an array of strings or
//    one string of comma/space-separated names; missing = no roles).
//
// Both answer a Principal (without policy; the caller adds it) or AuthenticationError with a reason
// for the log (the client gets only a generic message). Thread-safe (const after loading).
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "base/error/rr_error.hpp"
#include "server/gateway/auth/access_policy.hpp"

namespace rr::server::gateway::auth {

class BearerTokens {
public:
    /// Errors: InvalidArgument naming the line.
    static Result<BearerTokens> parse(std::string_view text);
    /// Errors: IOError, InvalidArgument (with the path).
    static Result<BearerTokens> load_file(const std::string& path);

    bool empty() const noexcept { return tokens_.empty(); }
    std::size_t size() const noexcept { return tokens_.size(); }
    /// Errors: AuthenticationError "unknown bearer token".
    Result<Principal> check(std::string_view token) const;

    static std::string sha256_hex(std::string_view text);

private:
    struct Entry {
        std::string name;
        std::vector<std::string> roles;
    };
    std::map<std::string, Entry, std::less<>> tokens_;  // SHA-256 hex → who
};

struct JwtSettings {
    std::string algorithm;  ///< "HS256", "RS256" or "ES256"
    std::string key;        ///< HS256: the secret bytes; RS256/ES256: the public key, PEM
    std::string audience;   ///< required
    std::string issuer;     ///< "" = not checked
    std::string user_claim = "sub";
    std::string roles_claim = "roles";
    std::chrono::seconds leeway{30};
};

class JwtVerifier {
public:
    /// Errors: InvalidArgument (unknown algorithm, empty key or audience, a PEM key that OpenSSL cannot
    /// read for RS256/ES256, an HS256 secret shorter than 32 bytes).
    static Result<JwtVerifier> create(JwtSettings settings);

    /// `now_unix`: seconds since the epoch. Errors: AuthenticationError with the reason ("bad
    /// signature or malformed token", "token expired", "token not valid yet", "wrong audience", …).
    Result<Principal> verify(std::string_view token, std::int64_t now_unix) const;
    const JwtSettings& settings() const noexcept { return settings_; }

private:
    JwtSettings settings_;
    int alg_ = 0;  // jwt_alg_t
};

/// Whether `text` looks like a JWT (three base64url parts separated by dots).
bool looks_like_jwt(std::string_view text) noexcept;

}  // namespace rr::server::gateway::auth
