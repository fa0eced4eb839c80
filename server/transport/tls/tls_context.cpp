#include "server/transport/tls/tls_context.hpp"

#include <arpa/inet.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include <openssl/err.h>
#include <openssl/pem.h>
#include <openssl/ssl.h>
#include <openssl/x509.h>
#include <openssl/x509v3.h>

#include <boost/asio/ssl/context.hpp>

namespace rr::server {

namespace ssl = boost::asio::ssl;

namespace {

// TLS 1.2 suites: forward secrecy (ECDHE) and AEAD only. TLS 1.3 suites are OpenSSL's (all AEAD).
constexpr const char* kTls12Ciphers =
    "ECDHE-ECDSA-AES128-GCM-SHA256:ECDHE-RSA-AES128-GCM-SHA256:ECDHE-ECDSA-AES256-GCM-SHA384:"
    "ECDHE-RSA-AES256-GCM-SHA384:ECDHE-ECDSA-CHACHA20-POLY1305:ECDHE-RSA-CHACHA20-POLY1305";
constexpr const char* kGroups = "X25519:P-256:P-384";

// The critical extensions of RR node certificates (leaf, intermediate, root; wire.md §7).
constexpr const char* kRRMarkers[] = {"1.3.6.1.4.1.45455.1.1.3.1", "1.3.6.1.4.1.45455.1.1.3.2",
                                      "1.3.6.1.4.1.45455.1.1.3.3"};

std::string openssl_error() {
    unsigned long e = ERR_get_error();
    std::string last;
    while (e) {  // the deepest error says the most; keep the last one queued
        char buf[256];
        ERR_error_string_n(e, buf, sizeof buf);
        last = buf;
        e = ERR_get_error();
    }
    return last.empty() ? std::string("unknown OpenSSL error") : last;
}

// Never prompt on the terminal for a key's passphrase: an encrypted key simply fails to load.
int no_passphrase(char*, int, int, void*) { return 0; }

// An unreadable file gets the system's reason, before OpenSSL's less helpful one.
std::optional<std::string> unreadable(const std::string& path) {
    if (path.empty()) return std::string("no file given");
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) return std::string("cannot read: ") + std::strerror(errno);
    std::fclose(f);
    return std::nullopt;
}

Unexpected config_error(const std::string& path, const std::string& what) {
    return fail(MessageErrorType::InvalidConfiguration, path + ": " + what);
}

std::string asn1_time_text(const ASN1_TIME* t) {
    BIO* b = BIO_new(BIO_s_mem());
    if (!b) return "?";
    ASN1_TIME_print(b, t);
    char* data = nullptr;
    long n = BIO_get_mem_data(b, &data);
    std::string out(data, static_cast<std::size_t>(n));
    BIO_free(b);
    return out;
}

std::string name_text(const X509_NAME* name) {
    BIO* b = BIO_new(BIO_s_mem());
    if (!b) return "?";
    X509_NAME_print_ex(b, name, 0, XN_FLAG_RFC2253);
    char* data = nullptr;
    long n = BIO_get_mem_data(b, &data);
    std::string out(data, static_cast<std::size_t>(n));
    BIO_free(b);
    return out;
}

bool looks_like_ip(const std::string& host) {
    unsigned char buf[16];
    return inet_pton(AF_INET, host.c_str(), buf) == 1 || inet_pton(AF_INET6, host.c_str(), buf) == 1;
}

// Loads `key_file` into `ctx` (whose certificate is already set). Tells "not a key" from "another
// certificate's key": OpenSSL 3 reports both from SSL_CTX_use_PrivateKey_file.
std::optional<std::string> use_private_key(SSL_CTX* ctx, const std::string& key_file, const std::string& cert_file) {
    BIO* bio = BIO_new_file(key_file.c_str(), "r");
    if (!bio) return "cannot read (" + openssl_error() + ")";
    EVP_PKEY* key = PEM_read_bio_PrivateKey(bio, nullptr, no_passphrase, nullptr);
    BIO_free(bio);
    if (!key) return "no unencrypted PEM private key (" + openssl_error() + ")";
    const bool ok = SSL_CTX_use_PrivateKey(ctx, key) == 1 && SSL_CTX_check_private_key(ctx) == 1;
    EVP_PKEY_free(key);
    ERR_clear_error();
    if (!ok) return "the private key does not match the certificate in " + cert_file;
    return std::nullopt;
}

// Common settings of every context.
void harden(SSL_CTX* ctx) {
    SSL_CTX_set_min_proto_version(ctx, TLS1_2_VERSION);
    SSL_CTX_set_max_proto_version(ctx, TLS1_3_VERSION);
    SSL_CTX_set_options(ctx, SSL_OP_NO_COMPRESSION | SSL_OP_NO_RENEGOTIATION | SSL_OP_CIPHER_SERVER_PREFERENCE);
    SSL_CTX_set_cipher_list(ctx, kTls12Ciphers);
    SSL_CTX_set1_groups_list(ctx, kGroups);
    SSL_CTX_set_default_passwd_cb(ctx, no_passphrase);
}

}  // namespace

int tls_verify_tolerating_rr_markers(int preverified, X509_STORE_CTX* ctx) {
    if (preverified) return 1;
    if (X509_STORE_CTX_get_error(ctx) != X509_V_ERR_UNHANDLED_CRITICAL_EXTENSION) return 0;
    X509* cert = X509_STORE_CTX_get_current_cert(ctx);
    if (!cert) return 0;
    for (int i = 0; i < X509_get_ext_count(cert); ++i) {
        X509_EXTENSION* ext = X509_get_ext(cert, i);
        if (!ext || !X509_EXTENSION_get_critical(ext) || X509_supported_extension(ext)) continue;
        char oid[80] = {};
        OBJ_obj2txt(oid, sizeof oid, X509_EXTENSION_get_object(ext), 1);
        bool marker = false;
        for (const char* m : kRRMarkers) marker = marker || std::strcmp(oid, m) == 0;
        if (!marker) return 0;  // some other critical extension nobody here understands
    }
    return 1;
}

Result<TlsContextPtr> make_tls_server_context(const std::string& certificate, const std::string& private_key,
                                              const std::string& client_ca) {
    if (auto why = unreadable(certificate)) return config_error(certificate, *why);
    if (auto why = unreadable(private_key)) return config_error(private_key, *why);
    if (!client_ca.empty())
        if (auto why = unreadable(client_ca)) return config_error(client_ca, *why);

    auto ctx = std::make_shared<ssl::context>(ssl::context::tls_server);
    SSL_CTX* native = ctx->native_handle();
    harden(native);
    ERR_clear_error();
    if (SSL_CTX_use_certificate_chain_file(native, certificate.c_str()) != 1)
        return config_error(certificate, "no PEM certificate chain (" + openssl_error() + ")");
    if (auto why = use_private_key(native, private_key, certificate)) return config_error(private_key, *why);
    X509* leaf = SSL_CTX_get0_certificate(native);
    if (!leaf) return config_error(certificate, "no certificate");
    if (X509_cmp_current_time(X509_get0_notAfter(leaf)) < 0)
        return config_error(certificate, "the certificate expired on " + asn1_time_text(X509_get0_notAfter(leaf)));
    if (X509_cmp_current_time(X509_get0_notBefore(leaf)) > 0)
        return config_error(certificate,
                            "the certificate is not valid before " + asn1_time_text(X509_get0_notBefore(leaf)));

    if (!client_ca.empty()) {
        if (SSL_CTX_load_verify_locations(native, client_ca.c_str(), nullptr) != 1)
            return config_error(client_ca, "no PEM CA certificate (" + openssl_error() + ")");
        STACK_OF(X509_NAME)* names = SSL_load_client_CA_file(client_ca.c_str());
        if (!names) return config_error(client_ca, "no PEM CA certificate (" + openssl_error() + ")");
        SSL_CTX_set_client_CA_list(native, names);  // tells clients which issuer to present
        SSL_CTX_set_verify(native, SSL_VERIFY_PEER | SSL_VERIFY_FAIL_IF_NO_PEER_CERT, tls_verify_tolerating_rr_markers);
        // Session resumption needs a context id once client certificates are verified.
        static constexpr unsigned char kSessionId[] = "rr-gateway";
        SSL_CTX_set_session_id_context(native, kSessionId, sizeof kSessionId - 1);
    } else {
        SSL_CTX_set_verify(native, SSL_VERIFY_NONE, nullptr);
    }
    return ctx;
}

Result<TlsServerCredentials::Contexts> TlsServerCredentials::build(const TlsServerFiles& files) {
    Contexts c;
    auto direct = make_tls_server_context(files.certificate, files.private_key, files.client_ca);
    if (!direct) return direct.take_error();
    c.direct = *direct;
    auto describe_leaf = [](const TlsContextPtr& ctx) {
        X509* leaf = SSL_CTX_get0_certificate(ctx->native_handle());
        return name_text(X509_get_subject_name(leaf)) + ", valid until " + asn1_time_text(X509_get0_notAfter(leaf));
    };
    c.description = describe_leaf(c.direct);
    if (files.node_certificate.empty() != files.node_private_key.empty())
        return config_error(files.node_certificate.empty() ? files.node_private_key : files.node_certificate,
                            "a node certificate needs both node_certificate and node_private_key");
    if (!files.node_certificate.empty()) {
        auto node = make_tls_server_context(files.node_certificate, files.node_private_key, files.client_ca);
        if (!node) return node.take_error();
        c.starttls = *node;
        c.description += "; rrs+tcp: " + describe_leaf(c.starttls);
    } else {
        c.starttls = c.direct;
    }
    return c;
}

Result<std::shared_ptr<TlsServerCredentials>> TlsServerCredentials::load(TlsServerFiles files) {
    auto contexts = build(files);
    if (!contexts) return contexts.take_error();
    std::shared_ptr<TlsServerCredentials> c(new TlsServerCredentials(std::move(files)));
    c->current_ = std::move(*contexts);
    return c;
}

Result<void> TlsServerCredentials::reload() {
    auto contexts = build(files_);
    if (!contexts) return contexts.take_error();
    std::lock_guard lock(mutex_);
    current_ = std::move(*contexts);
    return {};
}

TlsContextPtr TlsServerCredentials::direct() const {
    std::lock_guard lock(mutex_);
    return current_.direct;
}

TlsContextPtr TlsServerCredentials::starttls() const {
    std::lock_guard lock(mutex_);
    return current_.starttls;
}

std::string TlsServerCredentials::describe() const {
    std::lock_guard lock(mutex_);
    return current_.description;
}

Result<TlsContextPtr> make_tls_client_context(const TlsClientFiles& files) {
    auto ctx = std::make_shared<ssl::context>(ssl::context::tls_client);
    SSL_CTX* native = ctx->native_handle();
    harden(native);
    ERR_clear_error();
    if (files.ca.empty()) {
        if (SSL_CTX_set_default_verify_paths(native) != 1)
            return fail(MessageErrorType::ConnectionError, "TLS: cannot load the system's trusted certificates: " + openssl_error());
    } else {
        if (auto why = unreadable(files.ca))
            return fail(MessageErrorType::ConnectionError, "TLS: cannot load the trusted certificates from " + files.ca + ": " + *why);
        if (SSL_CTX_load_verify_locations(native, files.ca.c_str(), nullptr) != 1)
            return fail(MessageErrorType::ConnectionError,
                        "TLS: cannot load the trusted certificates from " + files.ca + ": " + openssl_error());
    }
    if (!files.certificate.empty() || !files.private_key.empty()) {
        const std::string& cert = files.certificate;
        const std::string& key = files.private_key.empty() ? files.certificate : files.private_key;
        if (auto why = unreadable(cert)) return fail(MessageErrorType::ConnectionError, "TLS: " + cert + ": " + *why);
        if (auto why = unreadable(key)) return fail(MessageErrorType::ConnectionError, "TLS: " + key + ": " + *why);
        if (SSL_CTX_use_certificate_chain_file(native, cert.c_str()) != 1)
            return fail(MessageErrorType::ConnectionError, "TLS: " + cert + ": no PEM certificate chain (" + openssl_error() + ")");
        if (auto why = use_private_key(native, key, cert))
            return fail(MessageErrorType::ConnectionError, "TLS: " + key + ": " + *why);
    }
    SSL_CTX_set_verify(native, SSL_VERIFY_PEER, tls_verify_tolerating_rr_markers);
    return ctx;
}

Result<void> verify_rrs_server_name(SSL* ssl, const std::string& host, const NodeID& node) {
    X509* cert = SSL_get0_peer_certificate(ssl);
    if (!cert) return fail(MessageErrorType::AuthenticationError, "TLS: the server sent no certificate");
    // An IP address is matched against IP subject alternative names, a name against DNS ones.
    const bool is_ip = looks_like_ip(host);
    if (!host.empty() && (is_ip ? X509_check_ip_asc(cert, host.c_str(), 0) == 1
                                : X509_check_host(cert, host.c_str(), host.size(), 0, nullptr) == 1))
        return {};
    char subject[256] = {};
    X509_NAME_oneline(X509_get_subject_name(cert), subject, sizeof subject);
    const std::string node_subject = "/CN=Robot Raconteur Node " + node.to_braced_string();
    if (!node.is_any() && node_subject == subject) return {};
    return fail(MessageErrorType::AuthenticationError,
                "TLS: the server's certificate (" + name_text(X509_get_subject_name(cert)) + ") names neither " + host +
                    (node.is_any() ? std::string() : " nor Robot Raconteur Node " + node.to_braced_string()));
}

std::string tls_peer_subject(SSL* ssl) {
    X509* cert = SSL_get0_peer_certificate(ssl);
    if (!cert) return {};
    return name_text(X509_get_subject_name(cert)) + " (issuer " + name_text(X509_get_issuer_name(cert)) + ")";
}

}  // namespace rr::server
