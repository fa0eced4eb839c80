// The STARTTLS exchange of `rrs+tcp` (wire.md §7; CORE TcpTransport.cpp), sans-IO: the plain message
// pair that comes before the TLS handshake on the same socket. The TLS handshake itself, certificates
// and the socket are the host's (server/transport).
//
//   client → server   v2 message, one entry StreamOp (1) `STARTTLS`; header ReceiverNodeID /
//                     ReceiverNodeName = the node asked for in the URL (zero / empty = any);
//                     SenderNodeID zero (as CORE); element `mutualauth` = string "true" only when the
//                     client will present a certificate of its own.
//   server → client   StreamOpRet (2) `STARTTLS`, header Sender = the server's NodeID/NodeName,
//                     Receiver = the request's sender; `mutualauth` = "true" echoed when asked (and,
//                     here, only when client certificates are really verified). Or an
//                     error entry: NodeNotFound "Node not found" (another node was asked for),
//                     ConnectionError "Server certificate not loaded" (no TLS on this node).
//   then              the TLS handshake (client = TLS client), then CreateConnection inside TLS.
//
// Neither side may send anything else before the handshake, so both objects say how many bytes they
// still want (bytes_wanted()): a host that reads at most that many never consumes a byte of the TLS
// handshake. Not thread-safe; one owner drives each object.
#pragma once

#include <chrono>
#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "base/codec/limits.hpp"
#include "base/error/rr_error.hpp"
#include "base/names/node_id.hpp"
#include "core/session/stream_connection.hpp"

namespace rr {

/// MemberName of the StreamOp.
inline constexpr std::string_view kStartTlsOp = "STARTTLS";
/// Largest STARTTLS request or reply accepted, bytes (the real ones are under 200 bytes; CORE's are
/// bounded only by the pre-session limit). A larger first message is not STARTTLS for the server.
inline constexpr std::size_t kMaxStartTlsMessageBytes = 16 * 1024;

// --- client ----------------------------------------------------------------------------------------

struct StartTlsClientConfig {
    /// The node asked for in the URL (`nodeid=`, `nodename=`); zero / empty = any.
    NodeID target_node_id;
    std::string target_node_name;
    /// The client has a certificate and will present it (asks for mutual authentication).
    bool mutual_auth = false;
    /// How long the server may take to answer (CORE: 5 s).
    std::chrono::milliseconds timeout{5000};
};

/// What the server's STARTTLS reply established.
struct StartTlsResult {
    /// The NodeID the server's certificate must name (wire.md §7 step 4): the URL's NodeID when it
    /// gave one, else the SenderNodeID of the reply.
    NodeID remote_node_id;
    std::string remote_node_name;
    /// The server echoed `mutualauth`.
    bool mutual_auth = false;
};

enum class StartTlsState : std::uint8_t { waiting, done, failed };

class StartTlsClient {
public:
    /// Builds the request at once (request()).
    StartTlsClient(StartTlsClientConfig config, MonoTime now);

    /// The request's bytes, to be written before anything else on the connection.
    std::span<const std::byte> request() const noexcept { return request_; }

    /// Bytes the reply still needs (the preamble first, then the rest of the message); 0 when not
    /// waiting. Reading no more than this never consumes a byte of the TLS handshake.
    std::size_t bytes_wanted() const noexcept;

    /// Consumes server bytes, in any split. Bytes past the reply, a reply over kMaxStartTlsMessageBytes, a
    /// reply that does not decode, or anything but one StreamOpRet `STARTTLS` entry: failed with
    /// ProtocolError. An error entry: failed with that error (e.g. NodeNotFound, ConnectionError
    /// "Server certificate not loaded"). A reply from another node than the one asked for:
    /// failed with ConnectionError "Could not create TLS connection" (as CORE).
    void feed(std::span<const std::byte> bytes, MonoTime now);

    StartTlsState state() const noexcept { return state_; }
    /// Valid in state done.
    const StartTlsResult& result() const noexcept { return result_; }
    /// Valid in state failed.
    const RRError& error() const noexcept { return error_; }

    /// The reply deadline while waiting.
    std::optional<MonoTime> next_deadline() const noexcept;
    /// Past the deadline: failed with ConnectionError "STARTTLS timed out".
    void on_timer(MonoTime now);

private:
    void fail_with(RRError e);
    void handle_reply();

    StartTlsClientConfig config_;
    std::vector<std::byte> request_;
    std::vector<std::byte> reply_;
    std::size_t reply_size_ = 0;  // MessageSize once the preamble is in
    MonoTime deadline_;
    StartTlsState state_ = StartTlsState::waiting;
    StartTlsResult result_;
    RRError error_;
};

// --- server ----------------------------------------------------------------------------------------

struct StartTlsServerConfig {
    NodeID local_node_id;
    std::string local_node_name;
    /// False: STARTTLS is refused with ConnectionError "Server certificate not loaded".
    bool certificate_loaded = true;
    /// The TLS handshake will ask for and verify client certificates: `mutualauth` is echoed to a
    /// client that asked for it (CORE echoes whenever asked; we say it only when it is true).
    bool verifies_client_certificates = false;
};

/// What the first message of an accepted `RRAC` connection is.
enum class FirstMessage : std::uint8_t {
    need_more,  ///< read up to bytes_wanted() more
    plain,      ///< not STARTTLS: run the ordinary stream protocol over received() (replayed)
    start_tls,  ///< write reply(), then the TLS handshake as server
    refused,    ///< write reply() (an error entry), then close
};

class StartTlsServer {
public:
    explicit StartTlsServer(StartTlsServerConfig config);

    /// Bytes the first message still needs; 0 once decided.
    std::size_t bytes_wanted() const noexcept;
    /// Consumes the connection's first bytes (beginning with `RRAC`, in any split). Anything that is
    /// not a well-formed single-entry StreamOp `STARTTLS` is `plain`: the ordinary stream protocol
    /// then reports its own error for it. More bytes than bytes_wanted() are kept for received().
    void feed(std::span<const std::byte> bytes);

    FirstMessage kind() const noexcept { return kind_; }
    /// Every byte fed so far (to replay into the stream protocol when plain).
    std::span<const std::byte> received() const noexcept { return received_; }
    /// The reply to write (start_tls, refused).
    std::span<const std::byte> reply() const noexcept { return reply_; }
    /// The client asked for mutual authentication (`mutualauth` "true").
    bool mutual_auth_requested() const noexcept { return mutual_auth_; }
    /// Why it was refused (refused).
    const RRError& refusal() const noexcept { return refusal_; }

private:
    void decide();

    StartTlsServerConfig config_;
    std::vector<std::byte> received_;
    std::vector<std::byte> reply_;
    FirstMessage kind_ = FirstMessage::need_more;
    bool mutual_auth_ = false;
    RRError refusal_;
};

}  // namespace rr
