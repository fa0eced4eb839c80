#include "server/gateway/auth/token_auth.hpp"

#include "server/common/digest_hex.hpp"

#include <cerrno>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <sstream>

#include <jwt.h>
#include <nlohmann/json.hpp>
#include <openssl/evp.h>
#include <openssl/pem.h>

namespace rr::server::gateway::auth {
namespace {

std::vector<std::string_view> fields(std::string_view line) {
    std::vector<std::string_view> out;
    std::size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
        std::size_t j = i;
        while (j < line.size() && line[j] != ' ' && line[j] != '\t' && line[j] != '\r') ++j;
        if (j > i) out.push_back(line.substr(i, j - i));
        i = j;
    }
    return out;
}

std::vector<std::string> split_roles(std::string_view s) {
    std::vector<std::string> out;
    if (s == "_") return out;
    std::size_t i = 0;
    while (i <= s.size()) {
        auto j = s.find_first_of(", ", i);
        if (j == std::string_view::npos) j = s.size();
        if (j > i) out.emplace_back(s.substr(i, j - i));
        i = j + 1;
    }
    return out;
}

bool token_char(char c) {
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '.' || c == '_' ||
           c == '~' || c == '+' || c == '/' || c == '=' || c == '-';
}

Unexpected auth_error(std::string why) { return fail(MessageErrorType::AuthenticationError, std::move(why)); }

struct JwtFree {
    void operator()(jwt_t* j) const { jwt_free(j); }
};

}  // namespace

std::string BearerTokens::sha256_hex(std::string_view text) { return server::sha256_hex(text); }

Result<BearerTokens> BearerTokens::parse(std::string_view text) {
    BearerTokens t;
    std::size_t line_no = 0;
    while (!text.empty()) {
        auto nl = text.find('\n');
        std::string_view line = text.substr(0, nl);
        text = nl == std::string_view::npos ? std::string_view{} : text.substr(nl + 1);
        ++line_no;
        auto f = fields(line);
        if (f.empty() || f[0].front() == '#') continue;
        auto bad = [&](const std::string& why) {
            return fail(MessageErrorType::InvalidArgument, "line " + std::to_string(line_no) + ": " + why);
        };
        if (f.size() != 3) return bad("expected `<token> <name> <roles>` (roles comma-separated, _ for none)");
        if (f[0].size() < 16) return bad("token shorter than 16 characters");
        for (char c : f[0])
            if (!token_char(c)) return bad("token has a character outside [A-Za-z0-9._~+/=-]");
        auto digest = sha256_hex(f[0]);
        if (t.tokens_.count(digest)) return bad("the same token appears twice");
        t.tokens_.emplace(std::move(digest), Entry{std::string(f[1]), split_roles(f[2])});
    }
    return t;
}

Result<BearerTokens> BearerTokens::load_file(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return fail(MessageErrorType::IOError, path + ": cannot read the token file");
    std::ostringstream ss;
    ss << in.rdbuf();
    auto r = parse(ss.str());
    if (!r) return fail(MessageErrorType::InvalidArgument, path + ": " + r.error().message);
    return r;
}

Result<Principal> BearerTokens::check(std::string_view token) const {
    auto it = tokens_.find(sha256_hex(token));
    if (it == tokens_.end()) return auth_error("unknown bearer token");
    Principal p;
    p.name = it->second.name;
    p.roles = it->second.roles;
    p.via = "token";
    return p;
}

bool looks_like_jwt(std::string_view t) noexcept {
    int dots = 0;
    for (char c : t) {
        if (c == '.') {
            ++dots;
        } else if (!((c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-' || c == '_' ||
                     c == '=')) {
            return false;
        }
    }
    return dots == 2;
}

Result<JwtVerifier> JwtVerifier::create(JwtSettings s) {
    JwtVerifier v;
    if (s.algorithm == "HS256") {
        v.alg_ = JWT_ALG_HS256;
        if (s.key.size() < 32) return fail(MessageErrorType::InvalidArgument, "an HS256 secret needs at least 32 bytes");
    } else if (s.algorithm == "RS256" || s.algorithm == "ES256") {
        v.alg_ = s.algorithm == "RS256" ? JWT_ALG_RS256 : JWT_ALG_ES256;
        std::unique_ptr<BIO, decltype(&BIO_free)> bio(BIO_new_mem_buf(s.key.data(), static_cast<int>(s.key.size())), BIO_free);
        EVP_PKEY* k = bio ? PEM_read_bio_PUBKEY(bio.get(), nullptr, nullptr, nullptr) : nullptr;
        if (!k) return fail(MessageErrorType::InvalidArgument, "the key is not a PEM public key (BEGIN PUBLIC KEY)");
        const int id = EVP_PKEY_get_base_id(k);
        EVP_PKEY_free(k);
        if ((v.alg_ == JWT_ALG_RS256) != (id == EVP_PKEY_RSA))
            return fail(MessageErrorType::InvalidArgument, "the public key's type does not match " + s.algorithm);
    } else {
        return fail(MessageErrorType::InvalidArgument, "unknown algorithm \"" + s.algorithm + "\" (HS256, RS256 or ES256)");
    }
    if (s.audience.empty()) return fail(MessageErrorType::InvalidArgument, "audience missing");
    if (s.user_claim.empty()) return fail(MessageErrorType::InvalidArgument, "user_claim is empty");
    v.settings_ = std::move(s);
    return v;
}

Result<Principal> JwtVerifier::verify(std::string_view token, std::int64_t now) const {
    if (token.size() > 16 * 1024 || !looks_like_jwt(token)) return auth_error("malformed token");
    const std::string text(token);
    jwt_t* raw = nullptr;
    // libjwt checks the signature with the key for the algorithm the header names; we then insist
    // that this algorithm is the configured one (so neither "none" nor an HS256 token "signed" with
    // the RSA public key as its secret gets through).
    const int rc = jwt_decode(&raw, text.c_str(), reinterpret_cast<const unsigned char*>(settings_.key.data()),
                              static_cast<int>(settings_.key.size()));
    std::unique_ptr<jwt_t, JwtFree> jwt(raw);
    if (rc != 0 || !jwt) return auth_error("bad signature or malformed token");
    if (static_cast<int>(jwt_get_alg(jwt.get())) != alg_) return auth_error("wrong algorithm");

    auto int_claim = [&](const char* name) -> std::optional<long> {
        errno = 0;
        long v = jwt_get_grant_int(jwt.get(), name);
        if (errno != 0) return std::nullopt;
        return v;
    };
    const long leeway = static_cast<long>(settings_.leeway.count());
    auto exp = int_claim("exp");
    if (!exp) return auth_error("token has no exp claim");
    if (now >= *exp + leeway) return auth_error("token expired");
    if (auto nbf = int_claim("nbf"); nbf && now + leeway < *nbf) return auth_error("token not valid yet");

    auto json_claim = [&](const char* name) -> nlohmann::json {
        char* s = jwt_get_grants_json(jwt.get(), name);
        if (!s) return nullptr;
        auto j = nlohmann::json::parse(s, nullptr, false);
        free(s);  // NOLINT: allocated by libjwt with malloc
        return j.is_discarded() ? nlohmann::json(nullptr) : j;
    };
    auto aud = json_claim("aud");
    bool aud_ok = aud.is_string() && aud.get<std::string>() == settings_.audience;
    if (aud.is_array())
        for (const auto& a : aud)
            if (a.is_string() && a.get<std::string>() == settings_.audience) aud_ok = true;
    if (!aud_ok) return auth_error("wrong audience");
    if (!settings_.issuer.empty()) {
        const char* iss = jwt_get_grant(jwt.get(), "iss");
        if (!iss || settings_.issuer != iss) return auth_error("wrong issuer");
    }
    const char* user = jwt_get_grant(jwt.get(), settings_.user_claim.c_str());
    if (!user || !*user) return auth_error("token has no " + settings_.user_claim + " claim");
    Principal p;
    p.name = user;
    p.via = "jwt";
    if (!settings_.roles_claim.empty()) {
        auto roles = json_claim(settings_.roles_claim.c_str());
        if (roles.is_array()) {
            for (const auto& r : roles)
                if (r.is_string()) p.roles.push_back(r.get<std::string>());
        } else if (roles.is_string()) {
            p.roles = split_roles(roles.get<std::string>());
        }
    }
    return p;
}

}  // namespace rr::server::gateway::auth
