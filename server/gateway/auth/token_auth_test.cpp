#include "server/gateway/auth/token_auth.hpp"

#include <cstdlib>
#include <memory>

#include <catch2/catch.hpp>
#include <jwt.h>
#include <openssl/evp.h>
#include <openssl/pem.h>

using namespace rr::server::gateway::auth;

namespace {

constexpr std::int64_t kNow = 1800000000;
const std::string kSecret = "0123456789abcdef0123456789abcdef-test-secret";

struct KeyPair {
    std::string private_pem, public_pem;
};

std::string bio_text(BIO* b) {
    char* data = nullptr;
    long n = BIO_get_mem_data(b, &data);
    return std::string(data, static_cast<std::size_t>(n));
}

KeyPair make_keys(bool rsa) {
    EVP_PKEY* k = rsa ? EVP_PKEY_Q_keygen(nullptr, nullptr, "RSA", static_cast<size_t>(2048))
                      : EVP_PKEY_Q_keygen(nullptr, nullptr, "EC", "P-256");
    REQUIRE(k);
    std::unique_ptr<BIO, decltype(&BIO_free)> priv(BIO_new(BIO_s_mem()), BIO_free), pub(BIO_new(BIO_s_mem()), BIO_free);
    PEM_write_bio_PrivateKey(priv.get(), k, nullptr, nullptr, 0, nullptr, nullptr);
    PEM_write_bio_PUBKEY(pub.get(), k);
    EVP_PKEY_free(k);
    return {bio_text(priv.get()), bio_text(pub.get())};
}

// Claims as JSON text; signed with `alg` and `key`.
std::string make_jwt(jwt_alg_t alg, const std::string& key, const std::string& claims_json) {
    jwt_t* raw = nullptr;
    REQUIRE(jwt_new(&raw) == 0);
    std::unique_ptr<jwt_t, decltype(&jwt_free)> owner(raw, jwt_free);  // freed when a REQUIRE fails too
    jwt_t* j = owner.get();
    REQUIRE(jwt_add_grants_json(j, claims_json.c_str()) == 0);
    REQUIRE(jwt_set_alg(j, alg, alg == JWT_ALG_NONE ? nullptr : reinterpret_cast<const unsigned char*>(key.data()),
                        alg == JWT_ALG_NONE ? 0 : static_cast<int>(key.size())) == 0);
    char* s = jwt_encode_str(j);
    REQUIRE(s);
    std::string out(s);
    free(s);  // NOLINT: libjwt 1.10 allocates with malloc (no jwt_free_str yet)
    return out;
}

// `roles`: the roles claim's JSON value (libjwt refuses a duplicate key, so it is not added twice).
std::string claims(std::int64_t exp, std::string extra = "", std::string roles = R"(["viewer","driver"])") {
    return R"({"sub":"carol","aud":"rr-gateway","roles":)" + roles + R"(,"exp":)" + std::to_string(exp) + extra + "}";
}

JwtVerifier verifier(std::string alg, std::string key, std::string issuer = "") {
    JwtSettings s;
    s.algorithm = std::move(alg);
    s.key = std::move(key);
    s.audience = "rr-gateway";
    s.issuer = std::move(issuer);
    auto v = JwtVerifier::create(std::move(s));
    REQUIRE(v);
    return *v;
}

}  // namespace

TEST_CASE("gateway auth: bearer token file") {
    auto t = BearerTokens::parse("# token name roles\n"
                                 "s3cr3t-token-for-the-wall-display  wall  viewer\n"
                                 "\n"
                                 "another-very-long-token-1234 ci viewer,driver\n"
                                 "no-roles-token-abcdefgh nobody _\n");
    REQUIRE(t);
    CHECK(t->size() == 3);
    auto p = t->check("another-very-long-token-1234");
    REQUIRE(p);
    CHECK(p->name == "ci");
    CHECK(p->roles == std::vector<std::string>{"viewer", "driver"});
    CHECK(p->via == "token");
    CHECK(t->check("no-roles-token-abcdefgh")->roles.empty());
    CHECK_FALSE(t->check("another-very-long-token-1235"));
    CHECK_FALSE(t->check(""));
    auto short_tok = BearerTokens::parse("short wall viewer\n");
    REQUIRE_FALSE(short_tok);
    CHECK(short_tok.error().message.find("line 1") != std::string::npos);
    CHECK_FALSE(BearerTokens::parse("a-token-of-enough-length wall\n"));
    CHECK_FALSE(BearerTokens::parse("a-token-of-enough-length\"x wall viewer\n"));
    CHECK_FALSE(BearerTokens::parse("dup-token-1234567890 a x\ndup-token-1234567890 b y\n"));
    CHECK_FALSE(BearerTokens::load_file("/nonexistent/tokens.txt"));
}

TEST_CASE("gateway auth: JWT HS256 with exp, nbf, aud, iss") {
    auto v = verifier("HS256", kSecret, "https://idp.lab");
    const std::string iss = R"(,"iss":"https://idp.lab")";
    auto ok = v.verify(make_jwt(JWT_ALG_HS256, kSecret, claims(kNow + 600, iss)), kNow);
    REQUIRE(ok);
    CHECK(ok->name == "carol");
    CHECK(ok->roles == std::vector<std::string>{"viewer", "driver"});
    CHECK(ok->via == "jwt");

    auto reason = [&](const std::string& tok) {
        auto r = v.verify(tok, kNow);
        REQUIRE_FALSE(r);
        CHECK(r.error().type == rr::MessageErrorType::AuthenticationError);
        return r.error().message;
    };
    CHECK(reason(make_jwt(JWT_ALG_HS256, kSecret, claims(kNow - 100, iss))) == "token expired");
    // Within the 30 s leeway an expired token still passes.
    CHECK(v.verify(make_jwt(JWT_ALG_HS256, kSecret, claims(kNow - 10, iss)), kNow));
    CHECK(reason(make_jwt(JWT_ALG_HS256, kSecret, claims(kNow + 600, iss + R"(,"nbf":)" + std::to_string(kNow + 300)))) ==
          "token not valid yet");
    CHECK(v.verify(make_jwt(JWT_ALG_HS256, kSecret, claims(kNow + 600, iss + R"(,"nbf":)" + std::to_string(kNow - 5))), kNow));
    CHECK(reason(make_jwt(JWT_ALG_HS256, kSecret, R"({"sub":"carol","aud":"other","iss":"https://idp.lab","exp":)" +
                                                       std::to_string(kNow + 60) + "}")) == "wrong audience");
    CHECK(v.verify(make_jwt(JWT_ALG_HS256, kSecret, R"({"sub":"carol","aud":["x","rr-gateway"],"iss":"https://idp.lab","exp":)" +
                                                        std::to_string(kNow + 60) + "}"),
                   kNow));
    CHECK(reason(make_jwt(JWT_ALG_HS256, kSecret, R"({"sub":"carol","aud":"rr-gateway","iss":"https://idp.lab"})")) ==
          "token has no exp claim");
    CHECK(reason(make_jwt(JWT_ALG_HS256, kSecret, claims(kNow + 600, R"(,"iss":"https://evil")"))) == "wrong issuer");
    // Forged: signed with another secret; tampered payload; alg none.
    CHECK(reason(make_jwt(JWT_ALG_HS256, kSecret + "x", claims(kNow + 600, iss))) == "bad signature or malformed token");
    auto good = make_jwt(JWT_ALG_HS256, kSecret, claims(kNow + 600, iss));
    auto other = make_jwt(JWT_ALG_HS256, kSecret + "x", R"({"sub":"root","aud":"rr-gateway","roles":["admin"],"exp":)" +
                                                         std::to_string(kNow + 600) + iss + "}");
    auto spliced = good.substr(0, good.find('.')) + other.substr(other.find('.'), other.rfind('.') - other.find('.')) +
                   good.substr(good.rfind('.'));
    CHECK(reason(spliced) == "bad signature or malformed token");
    CHECK_FALSE(v.verify(make_jwt(JWT_ALG_NONE, "", claims(kNow + 600, iss)), kNow));
    CHECK(reason("not-a-jwt") == "malformed token");
    CHECK(reason("a.b.c") == "bad signature or malformed token");
    CHECK_FALSE(v.verify(std::string(20000, 'a'), kNow));
}

TEST_CASE("gateway auth: JWT ES256 and RS256 with public keys, no algorithm confusion") {
    auto ec = make_keys(false);
    auto v = verifier("ES256", ec.public_pem);
    CHECK(v.verify(make_jwt(JWT_ALG_ES256, ec.private_pem, claims(kNow + 60)), kNow));
    CHECK_FALSE(v.verify(make_jwt(JWT_ALG_ES256, make_keys(false).private_pem, claims(kNow + 60)), kNow));
    CHECK_FALSE(v.verify(make_jwt(JWT_ALG_ES256, ec.private_pem, claims(kNow - 60)), kNow));
    // HS256 "signed" with the public key text as the secret must not pass an ES256 verifier.
    CHECK_FALSE(v.verify(make_jwt(JWT_ALG_HS256, ec.public_pem, claims(kNow + 60)), kNow));

    auto rsa = make_keys(true);
    auto r = verifier("RS256", rsa.public_pem);
    auto ok = r.verify(make_jwt(JWT_ALG_RS256, rsa.private_pem, claims(kNow + 60, "", R"("viewer, driver")")), kNow);
    REQUIRE(ok);
    CHECK(ok->roles == std::vector<std::string>{"viewer", "driver"});
    CHECK_FALSE(r.verify(make_jwt(JWT_ALG_HS256, rsa.public_pem, claims(kNow + 60)), kNow));
    CHECK_FALSE(r.verify(make_jwt(JWT_ALG_RS256, make_keys(true).private_pem, claims(kNow + 60)), kNow));

    // Settings errors.
    JwtSettings s;
    s.algorithm = "ES256";
    s.key = rsa.public_pem;
    s.audience = "a";
    CHECK_FALSE(JwtVerifier::create(s));  // RSA key for ES256
    s.algorithm = "HS256";
    s.key = "short";
    CHECK_FALSE(JwtVerifier::create(s));
    s.algorithm = "PS256";
    CHECK_FALSE(JwtVerifier::create(s));
    s.algorithm = "RS256";
    s.key = "not a pem";
    CHECK_FALSE(JwtVerifier::create(s));
    s.key = rsa.public_pem;
    s.audience = "";
    CHECK_FALSE(JwtVerifier::create(s));
}
