// TLS settings of the gateway and its clients (docs/security.md): OpenSSL contexts built from ordinary
// PEM files, for
//   * the server side of the shared port: HTTPS/WSS (a TLS ClientHello as first bytes) and rrs+tcp
//     (STARTTLS, wire.md §7), optionally requiring client certificates (mTLS);
//   * the client side: rr+wss and rrs+tcp connections, trusting a given CA file or the system's store,
//     optionally presenting a certificate of their own.
// Every context allows TLS 1.2 and 1.3 only; TLS 1.2 is limited to ECDHE key exchange with AES-GCM or
// ChaCha20-Poly1305; no compression, no renegotiation. Certificate chains are verified by OpenSSL;
// the only unknown critical extensions tolerated are Robot Raconteur's node-certificate markers
// (1.3.6.1.4.1.45455.1.1.3.1/2/3, wire.md §7), so certificates issued for the official library verify
// when their root is given as the CA.
#pragma once

#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "base/error/rr_error.hpp"
#include "base/names/node_id.hpp"

typedef struct x509_store_ctx_st X509_STORE_CTX;
typedef struct ssl_st SSL;

namespace boost::asio::ssl {
class context;
}

namespace rr::server {

using TlsContextPtr = std::shared_ptr<boost::asio::ssl::context>;

/// PEM files of a TLS server identity.
struct TlsServerFiles {
    std::string certificate;  ///< certificate chain, leaf first
    std::string private_key;  ///< unencrypted private key of the leaf
    /// CA certificates that client certificates must chain to; "" = no client certificates asked for.
    /// When set, a client without a certificate that verifies is refused (mTLS).
    std::string client_ca;
    /// rrs+tcp (STARTTLS) only: another certificate and key, e.g. one naming the node as the official
    /// library expects (CN "Robot Raconteur Node {NodeID}" with its critical markers, which browsers
    /// refuse). "" = the certificate above.
    std::string node_certificate;
    std::string node_private_key;
};

/// A server context for `certificate` + `private_key`, asking for client certificates when
/// `client_ca` is set. Errors: InvalidConfiguration naming the file and the problem: unreadable
/// (system message), no PEM certificate / private key in it (encrypted keys are refused, never
/// prompted for), a key that does not match the certificate, a leaf certificate that has expired or
/// is not valid yet (with the date).
Result<TlsContextPtr> make_tls_server_context(const std::string& certificate, const std::string& private_key,
                                              const std::string& client_ca);

/// The server contexts in use, swapped by reload() (SIGHUP): a connection takes a context when it is
/// accepted and keeps it (OpenSSL reference-counts it), so open connections are never dropped and
/// new ones get the new certificate. Thread-safe.
class TlsServerCredentials {
public:
    /// Loads every file. Errors: as make_tls_server_context.
    static Result<std::shared_ptr<TlsServerCredentials>> load(TlsServerFiles files);

    /// Reads the files again. On success new connections use the new contexts; on error nothing
    /// changes and the error (as load()) is returned.
    Result<void> reload();

    /// The context for a connection whose first bytes are a TLS ClientHello (HTTPS, WSS, RR over TLS).
    TlsContextPtr direct() const;
    /// The context for rrs+tcp after STARTTLS.
    TlsContextPtr starttls() const;
    /// Client certificates are required (client_ca is set).
    bool requires_client_certificate() const { return !files_.client_ca.empty(); }
    const TlsServerFiles& files() const noexcept { return files_; }
    /// "CN=…, valid until …" of the leaf certificates in use, for logs.
    std::string describe() const;

private:
    explicit TlsServerCredentials(TlsServerFiles files) : files_(std::move(files)) {}
    struct Contexts {
        TlsContextPtr direct, starttls;
        std::string description;
    };
    static Result<Contexts> build(const TlsServerFiles& files);

    TlsServerFiles files_;
    mutable std::mutex mutex_;
    Contexts current_;
};

/// What a TLS client trusts and presents.
struct TlsClientFiles {
    std::string ca;           ///< PEM certificates to trust; "" = the system's store
    std::string certificate;  ///< own certificate chain (mTLS); "" = none
    std::string private_key;
};

/// A client context (verify_peer). Errors: ConnectionError "TLS: …" naming the file that cannot be
/// loaded.
Result<TlsContextPtr> make_tls_client_context(const TlsClientFiles& files);

/// OpenSSL verify callback shared by every context: accepts what OpenSSL accepted, plus certificates
/// whose only problem is a critical extension that is one of RR's node-certificate markers.
int tls_verify_tolerating_rr_markers(int preverified, X509_STORE_CTX* ctx);

/// After a client handshake for rrs+tcp: the server's leaf certificate must name `host` (DNS or IP
/// subject alternative name, as for HTTPS) or be the node certificate of `node` (subject exactly
/// CN=Robot Raconteur Node {node}, wire.md §7). Errors: AuthenticationError saying what it names.
Result<void> verify_rrs_server_name(SSL* ssl, const std::string& host, const NodeID& node);

/// "CN=… (issuer CN=…)" of the peer's certificate, or "" when it sent none (for logs).
std::string tls_peer_subject(SSL* ssl);

}  // namespace rr::server
