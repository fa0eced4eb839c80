// A native client session at the level of message entries: connects by URL (any transport of its
// TransportRegistry: rr+tcp, rr+ws, rr+wss, rr+local, …), runs
// core's ClientSession on a strand, and hands out replies and unsolicited entries. The gateway uses it to
// forward entries to devices without decoding them; the typed client is built the same way.
//
// Thread-safety: every public function may be called from any thread. Handlers run on the
// connection's strand: do not block in them.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <mutex>

#include <boost/asio/any_io_executor.hpp>

#include "base/names/connection_url.hpp"
#include "core/session/client_session.hpp"
#include "server/transport/connection_logic.hpp"
#include "server/transport/stream_pump.hpp"
#include "server/transport/transport_registry.hpp"

namespace rr::server {

struct RawClientOptions {
    NodeID local_node_id;          ///< all-zero: random
    std::string local_node_name;
    std::string username, password;
    /// Sent as `credentials` instead of {"password": password} when set (ClientSessionConfig::credentials).
    std::optional<MessageElement> credentials;
    bool enable_message4 = true;
    bool enable_string_table = true;
    std::chrono::milliseconds connect_timeout{5000};
    std::chrono::milliseconds request_timeout{15000};
    /// rr+wss, rrs+tcp: PEM file of the certificates to trust ("" = the system's).
    std::string tls_ca_file;
    /// TLS: own certificate chain and key (PEM) for servers that require client certificates.
    std::string tls_certificate_file, tls_private_key_file;
    /// WebSocket handshakes: Authorization header ("" = none).
    std::string http_authorization;
    Limits limits;
    /// Connectors by URL scheme (nullptr: default_transports()); the gateway passes its node's.
    const TransportRegistry* transports = nullptr;
};

/// The `credentials` a gateway's bearer token or JWT logs in with (docs/security.md "Native RR clients"):
/// the dictionary {"token": token}; the user name is then `<name>@token` or `<sub>@jwt`.
MessageElement token_credentials(const std::string& token);

class RawClient : public std::enable_shared_from_this<RawClient> {
public:
    using ConnectHandler = std::function<void(Result<std::shared_ptr<RawClient>>)>;
    using ReplyHandler = std::function<void(Result<MessageEntry>)>;
    using IncomingHandler = std::function<void(MessageEntry&&)>;
    using ClosedHandler = std::function<void(const RRError&)>;

    /// Connects to `url` (the URL must name a service) and establishes the client session.
    /// `incoming` receives entries the service sends unasked; `closed` is called once when the session
    /// ends after a successful connect. Both are set before any traffic flows.
    static void connect(boost::asio::any_io_executor executor, const ConnectionUrl& url, RawClientOptions options,
                        IncomingHandler incoming, ClosedHandler closed, ConnectHandler done);

    /// Sends a request; `done` gets the reply entry (whose Error field may be set) or a local error,
    /// exactly once: ConnectionError when the connection closes before the request is answered,
    /// including a request made while it closes.
    void request(MessageEntry entry, ReplyHandler done);
    /// Sends a request with its own timeout (0 = none).
    void request(MessageEntry entry, std::chrono::milliseconds timeout, ReplyHandler done);
    /// Sends an entry that gets no reply (pipe/wire packets, callback replies).
    void send(MessageEntry entry);
    /// DisconnectClient, then close. Also done when the last reference goes. `closed` (optional) is
    /// called once, on the connection's strand or at once, when the session has ended: the service
    /// answered DisconnectClient, or 500 ms passed without an answer (wire.md §6.6), or the connection
    /// closed, or it had ended before.
    void close(std::function<void()> closed = {});
    ~RawClient();

    const ClientSessionInfo& info() const noexcept { return info_; }
    const NodeID& remote_node_id() const noexcept { return remote_node_id_; }
    const std::string& remote_node_name() const noexcept { return remote_node_name_; }
    bool is_open() const noexcept { return open_.load(); }
    /// Bytes queued for sending (for backpressure decisions).
    std::size_t queued_bytes() const noexcept { return queued_.load(); }

    class Logic;

private:
    RawClient() = default;
    friend class Logic;
    void queue_request(MessageEntry&& entry, std::chrono::milliseconds timeout, ReplyHandler&& done);

    std::shared_ptr<Logic> logic_;
    std::weak_ptr<PumpHandle> pump_;
    ClientSessionInfo info_;
    NodeID remote_node_id_;
    std::string remote_node_name_;
    std::atomic<bool> open_{false};
    std::atomic<std::size_t> queued_{0};
};

}  // namespace rr::server
