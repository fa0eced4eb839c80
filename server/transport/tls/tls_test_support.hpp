// Test helpers for TLS: a throw-away PKI made with OpenSSL in a temporary folder (EC P-256 keys,
// SHA-256 signatures): CAs, server and client certificates with subject alternative names, expired
// and future certificates, RR node certificates with the critical marker extensions of wire.md §7.
#pragma once

#include <cstdio>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <unistd.h>

#include <openssl/evp.h>
#include <openssl/pem.h>
#include <openssl/x509.h>
#include <openssl/x509v3.h>

#include <catch2/catch.hpp>

namespace rr::server::testing {

class TestPki {
public:
    struct Issued {
        std::string cert;  ///< PEM file of the certificate (for a CA: the CA certificate)
        std::string key;   ///< PEM file of its private key
        X509* x509 = nullptr;
        EVP_PKEY* pkey = nullptr;
    };
    struct Spec {
        std::string cn;
        std::vector<std::string> sans;  ///< "DNS:localhost", "IP:127.0.0.1"
        long not_before_s = -3600;      ///< seconds from now
        long not_after_s = 86400;
        bool ca = false;
        bool client = false;            ///< extendedKeyUsage clientAuth (else serverAuth)
        const char* rr_marker = nullptr;  ///< e.g. "1.3.6.1.4.1.45455.1.1.3.3" (critical, BOOLEAN TRUE)
        std::vector<std::pair<std::string, std::string>> extra;  ///< more extensions (name, value)
    };

    TestPki() {
        char tmpl[] = "/tmp/rr_tls_test_XXXXXX";
        char* made = ::mkdtemp(tmpl);
        REQUIRE(made);
        dir = made;
    }
    ~TestPki() {
        for (auto& i : issued_) {
            X509_free(i.x509);
            EVP_PKEY_free(i.pkey);
        }
        std::error_code ec;
        std::filesystem::remove_all(dir, ec);
    }
    TestPki(const TestPki&) = delete;
    TestPki& operator=(const TestPki&) = delete;

    /// A self-signed CA.
    Issued ca(const std::string& name, const char* rr_marker = nullptr) {
        Spec s;
        s.cn = name;
        s.ca = true;
        s.rr_marker = rr_marker;
        return issue(nullptr, s, name);
    }

    /// A certificate issued by `issuer` (nullptr: self-signed), written as `<file>.pem` / `<file>.key`.
    Issued issue(const Issued* issuer, const Spec& spec, const std::string& file) {
        Issued out;
        out.pkey = EVP_EC_gen("P-256");
        REQUIRE(out.pkey);
        X509* x = X509_new();
        X509_set_version(x, 2);
        ASN1_INTEGER_set(X509_get_serialNumber(x), ++serial_);
        X509_gmtime_adj(X509_getm_notBefore(x), spec.not_before_s);
        X509_gmtime_adj(X509_getm_notAfter(x), spec.not_after_s);
        X509_set_pubkey(x, out.pkey);
        X509_NAME* name = X509_get_subject_name(x);
        X509_NAME_add_entry_by_txt(name, "CN", MBSTRING_UTF8, reinterpret_cast<const unsigned char*>(spec.cn.c_str()), -1, -1, 0);
        X509_set_issuer_name(x, issuer ? X509_get_subject_name(issuer->x509) : name);
        X509V3_CTX ctx;
        X509V3_set_ctx_nodb(&ctx);
        X509V3_set_ctx(&ctx, issuer ? issuer->x509 : x, x, nullptr, nullptr, 0);
        std::vector<std::pair<std::string, std::string>> exts;
        if (spec.ca) {
            exts = {{"basicConstraints", "critical,CA:TRUE"}, {"keyUsage", "critical,keyCertSign,cRLSign"}};
        } else {
            exts = {{"basicConstraints", "critical,CA:FALSE"},
                    {"keyUsage", "critical,digitalSignature,keyAgreement"},
                    {"extendedKeyUsage", spec.client ? "clientAuth" : "serverAuth"}};
        }
        exts.push_back({"subjectKeyIdentifier", "hash"});
        if (issuer) exts.push_back({"authorityKeyIdentifier", "keyid"});
        if (!spec.sans.empty()) {
            std::string v;
            for (const auto& s : spec.sans) v += (v.empty() ? "" : ",") + s;
            exts.push_back({"subjectAltName", v});
        }
        if (spec.rr_marker) exts.push_back({spec.rr_marker, "critical,ASN1:BOOLEAN:TRUE"});
        for (const auto& e : spec.extra) exts.push_back(e);
        for (const auto& [n, v] : exts) {
            X509_EXTENSION* e = X509V3_EXT_conf(nullptr, &ctx, n.c_str(), v.c_str());
            INFO(n << " = " << v);
            REQUIRE(e);
            X509_add_ext(x, e, -1);
            X509_EXTENSION_free(e);
        }
        REQUIRE(X509_sign(x, issuer ? issuer->pkey : out.pkey, EVP_sha256()) > 0);
        out.x509 = x;
        out.cert = dir + "/" + file + ".pem";
        out.key = dir + "/" + file + ".key";
        write_cert(out.cert, {x});
        write_key(out.key, out.pkey);
        issued_.push_back(out);
        return out;
    }

    /// A PEM file holding these certificates in this order (a chain, leaf first).
    std::string chain(const std::string& file, const std::vector<const Issued*>& certs) {
        std::vector<X509*> xs;
        for (auto* c : certs) xs.push_back(c->x509);
        std::string path = dir + "/" + file;
        write_cert(path, xs);
        return path;
    }

    /// `key` written encrypted with a passphrase.
    std::string encrypted_key(const Issued& i, const std::string& file) {
        std::string path = dir + "/" + file;
        std::FILE* f = std::fopen(path.c_str(), "wb");
        REQUIRE(f);
        static const char kPass[] = "secret";
        REQUIRE(PEM_write_PrivateKey(f, i.pkey, EVP_aes_128_cbc(), reinterpret_cast<const unsigned char*>(kPass),
                                     sizeof kPass - 1, nullptr, nullptr) == 1);
        std::fclose(f);
        return path;
    }

    std::string write_text(const std::string& file, const std::string& text) {
        std::string path = dir + "/" + file;
        std::FILE* f = std::fopen(path.c_str(), "wb");
        REQUIRE(f);
        std::fwrite(text.data(), 1, text.size(), f);
        std::fclose(f);
        return path;
    }

    std::string dir;

private:
    static void write_cert(const std::string& path, const std::vector<X509*>& xs) {
        std::FILE* f = std::fopen(path.c_str(), "wb");
        REQUIRE(f);
        for (X509* x : xs) REQUIRE(PEM_write_X509(f, x) == 1);
        std::fclose(f);
    }
    static void write_key(const std::string& path, EVP_PKEY* k) {
        std::FILE* f = std::fopen(path.c_str(), "wb");
        REQUIRE(f);
        REQUIRE(PEM_write_PrivateKey(f, k, nullptr, nullptr, 0, nullptr, nullptr) == 1);
        std::fclose(f);
    }

    std::vector<Issued> issued_;
    long serial_ = 1;
};

}  // namespace rr::server::testing
