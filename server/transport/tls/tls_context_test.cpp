// TLS contexts from PEM files: what loads, and the error for each bad file (named, with the reason);
// reloading swaps the context for new connections and keeps the old one on a bad file.
#include <catch2/catch.hpp>

#include <openssl/ssl.h>

#include <boost/asio/ssl/context.hpp>

#include "server/transport/tls/tls_context.hpp"
#include "server/transport/tls/tls_test_support.hpp"

using namespace rr;
using namespace rr::server;
using rr::server::testing::TestPki;

namespace {

std::string leaf_cn(const TlsContextPtr& ctx) {
    X509* leaf = SSL_CTX_get0_certificate(ctx->native_handle());
    REQUIRE(leaf);
    char cn[256] = {};
    X509_NAME_get_text_by_NID(X509_get_subject_name(leaf), NID_commonName, cn, sizeof cn);
    return cn;
}

TestPki::Issued server_cert(TestPki& pki, const TestPki::Issued& ca, const std::string& cn, long not_before = -3600,
                            long not_after = 86400) {
    TestPki::Spec s;
    s.cn = cn;
    s.sans = {"DNS:localhost", "IP:127.0.0.1"};
    s.not_before_s = not_before;
    s.not_after_s = not_after;
    return pki.issue(&ca, s, cn);
}

}  // namespace

TEST_CASE("tls: a server context loads a chain and its key, TLS 1.2 and 1.3 only") {
    TestPki pki;
    auto ca = pki.ca("Test CA");
    auto leaf = server_cert(pki, ca, "gateway.test");
    auto chain = pki.chain("chain.pem", {&leaf, &ca});
    auto ctx = make_tls_server_context(chain, leaf.key, "");
    REQUIRE(ctx);
    CHECK(leaf_cn(*ctx) == "gateway.test");
    CHECK(SSL_CTX_get_min_proto_version((*ctx)->native_handle()) == TLS1_2_VERSION);
    CHECK(SSL_CTX_get_max_proto_version((*ctx)->native_handle()) == TLS1_3_VERSION);
    CHECK((SSL_CTX_get_options((*ctx)->native_handle()) & SSL_OP_NO_COMPRESSION) != 0);
    CHECK((SSL_CTX_get_options((*ctx)->native_handle()) & SSL_OP_NO_RENEGOTIATION) != 0);
    CHECK(SSL_CTX_get_verify_mode((*ctx)->native_handle()) == SSL_VERIFY_NONE);

    // With a client CA: client certificates are required.
    auto mtls = make_tls_server_context(chain, leaf.key, ca.cert);
    REQUIRE(mtls);
    CHECK(SSL_CTX_get_verify_mode((*mtls)->native_handle()) == (SSL_VERIFY_PEER | SSL_VERIFY_FAIL_IF_NO_PEER_CERT));
}

TEST_CASE("tls: every bad server file is a configuration error naming the file") {
    TestPki pki;
    auto ca = pki.ca("Test CA");
    auto leaf = server_cert(pki, ca, "good");
    auto other = server_cert(pki, ca, "other");

    auto expect_error = [](const Result<TlsContextPtr>& r, const std::string& file, const std::string& what) {
        REQUIRE_FALSE(r);
        CHECK(r.error().type == MessageErrorType::InvalidConfiguration);
        CHECK_THAT(r.error().message, Catch::StartsWith(file + ": "));
        CHECK_THAT(r.error().message, Catch::Contains(what));
    };
    SECTION("missing certificate file") {
        expect_error(make_tls_server_context(pki.dir + "/nope.pem", leaf.key, ""), pki.dir + "/nope.pem",
                     "cannot read: No such file or directory");
    }
    SECTION("missing key file") {
        expect_error(make_tls_server_context(leaf.cert, pki.dir + "/nope.key", ""), pki.dir + "/nope.key", "cannot read");
    }
    SECTION("unreadable client CA") {
        expect_error(make_tls_server_context(leaf.cert, leaf.key, pki.dir + "/ca-nope.pem"), pki.dir + "/ca-nope.pem",
                     "cannot read");
    }
    SECTION("not PEM") {
        auto junk = pki.write_text("junk.pem", "this is not a certificate\n");
        expect_error(make_tls_server_context(junk, leaf.key, ""), junk, "no PEM certificate chain");
        expect_error(make_tls_server_context(leaf.cert, junk, ""), junk, "no unencrypted PEM private key");
        expect_error(make_tls_server_context(leaf.cert, leaf.key, junk), junk, "no PEM CA certificate");
    }
    SECTION("a key of another certificate") {
        expect_error(make_tls_server_context(leaf.cert, other.key, ""), other.key, "does not match the certificate in " + leaf.cert);
    }
    SECTION("an encrypted key is refused, never prompted for") {
        auto enc = pki.encrypted_key(leaf, "enc.key");
        expect_error(make_tls_server_context(leaf.cert, enc, ""), enc, "no unencrypted PEM private key");
    }
    SECTION("an expired certificate") {
        auto old = server_cert(pki, ca, "old", -7200, -3600);
        expect_error(make_tls_server_context(old.cert, old.key, ""), old.cert, "the certificate expired on");
    }
    SECTION("a certificate not valid yet") {
        auto future = server_cert(pki, ca, "future", 3600, 7200);
        expect_error(make_tls_server_context(future.cert, future.key, ""), future.cert, "not valid before");
    }
}

TEST_CASE("tls: reload swaps the context for new connections and keeps it on a bad file") {
    TestPki pki;
    auto ca = pki.ca("Test CA");
    auto first = server_cert(pki, ca, "first");
    const std::string cert = pki.dir + "/live.pem", key = pki.dir + "/live.key";
    std::filesystem::copy_file(first.cert, cert);
    std::filesystem::copy_file(first.key, key);

    auto creds = TlsServerCredentials::load(TlsServerFiles{cert, key, "", "", ""});
    REQUIRE(creds);
    auto before = (*creds)->direct();
    CHECK(leaf_cn(before) == "first");
    CHECK((*creds)->starttls() == before);  // no node certificate: the same context
    CHECK_THAT((*creds)->describe(), Catch::Contains("CN=first") && Catch::Contains("valid until"));

    // A new certificate: new connections get it; the old context stays valid for whoever holds it.
    auto second = server_cert(pki, ca, "second");
    std::filesystem::copy_file(second.cert, cert, std::filesystem::copy_options::overwrite_existing);
    std::filesystem::copy_file(second.key, key, std::filesystem::copy_options::overwrite_existing);
    REQUIRE((*creds)->reload());
    CHECK(leaf_cn((*creds)->direct()) == "second");
    CHECK(leaf_cn(before) == "first");

    // A key that does not match: an error, and the second certificate stays in use.
    std::filesystem::copy_file(first.key, key, std::filesystem::copy_options::overwrite_existing);
    auto bad = (*creds)->reload();
    REQUIRE_FALSE(bad);
    CHECK_THAT(bad.error().message, Catch::Contains("does not match"));
    CHECK(leaf_cn((*creds)->direct()) == "second");
}

TEST_CASE("tls: a node certificate for rrs+tcp next to the web certificate") {
    TestPki pki;
    auto ca = pki.ca("Test CA");
    auto web = server_cert(pki, ca, "web");
    TestPki::Spec s;
    s.cn = "Robot Raconteur Node {12345678-9abc-def0-1234-56789abcdef0}";
    s.rr_marker = "1.3.6.1.4.1.45455.1.1.3.3";
    auto node = pki.issue(&ca, s, "node");
    auto creds = TlsServerCredentials::load(TlsServerFiles{web.cert, web.key, "", node.cert, node.key});
    REQUIRE(creds);
    CHECK(leaf_cn((*creds)->direct()) == "web");
    CHECK(leaf_cn((*creds)->starttls()) == s.cn);
    auto half = TlsServerCredentials::load(TlsServerFiles{web.cert, web.key, "", node.cert, ""});
    REQUIRE_FALSE(half);
    CHECK_THAT(half.error().message, Catch::Contains("node_certificate and node_private_key"));
}

TEST_CASE("tls: client contexts name the file they cannot load") {
    TestPki pki;
    auto ca = pki.ca("Test CA");
    auto junk = pki.write_text("junk.pem", "no certificates here\n");
    CHECK(make_tls_client_context(TlsClientFiles{}));
    CHECK(make_tls_client_context(TlsClientFiles{ca.cert, "", ""}));
    auto missing = make_tls_client_context(TlsClientFiles{pki.dir + "/none.pem", "", ""});
    REQUIRE_FALSE(missing);
    CHECK(missing.error().type == MessageErrorType::ConnectionError);
    CHECK_THAT(missing.error().message, Catch::Contains(pki.dir + "/none.pem") && Catch::Contains("No such file"));
    auto bad = make_tls_client_context(TlsClientFiles{junk, "", ""});
    REQUIRE_FALSE(bad);
    CHECK_THAT(bad.error().message, Catch::Contains(junk));
    TestPki::Spec cs;
    cs.cn = "client";
    cs.client = true;
    auto client = pki.issue(&ca, cs, "client");
    auto other = pki.issue(&ca, cs, "other");
    CHECK(make_tls_client_context(TlsClientFiles{ca.cert, client.cert, client.key}));
    auto mismatch = make_tls_client_context(TlsClientFiles{ca.cert, client.cert, other.key});
    REQUIRE_FALSE(mismatch);
    CHECK_THAT(mismatch.error().message, Catch::Contains("does not match"));
}
