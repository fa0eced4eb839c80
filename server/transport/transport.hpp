// The transport seam (docs/architecture.md "Transports"). A transport moves the bytes of RR
// connections; it never interprets them. Each transport has up to two halves:
//   * a Connector (client side), chosen by URL scheme through a TransportRegistry: it opens a byte
//     stream to a ConnectionUrl and runs a ConnectionLogic (core's ClientSession/ClientContext) over it
//     in a StreamPump;
//   * a Listener (service side): it accepts byte streams and hands each to a ConnectionSink (the node),
//     which gives back the ConnectionLogic (core's ServiceSession) to run over it.
// A byte stream is any Asio-style stream with get_executor(), async_read_some(), async_write_some()
// and close() or lowest_layer(): a TCP or Unix socket, a WebSocket (WebSocketByteStream), a TLS stream.
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <boost/asio/any_io_executor.hpp>

#include "base/error/rr_error.hpp"
#include "base/names/connection_url.hpp"
#include "server/transport/connection_logic.hpp"
#include "server/transport/stream_pump.hpp"

namespace rr::server {

/// What a connector needs besides the URL.
struct ConnectOptions {
    /// Opening the byte stream, including TLS and WebSocket handshakes (wire.md §13: 5 s).
    std::chrono::milliseconds connect_timeout{5000};
    /// TLS (rr+wss, rrs+tcp): PEM file of the certificates to trust ("" = the system's).
    std::string tls_ca_file;
    /// TLS: this client's own certificate chain and private key (PEM), presented when the server asks
    /// (mTLS; rrs+tcp then also asks for mutual authentication in STARTTLS). "" = none.
    std::string tls_certificate_file;
    std::string tls_private_key_file;
    /// WebSocket handshakes: the Authorization header ("" = none), for a reverse proxy's login.
    std::string http_authorization;
};

/// Called once, on the strand: the pump (already started) or the error (ConnectionError naming the
/// step that failed).
using ConnectHandler = std::function<void(Result<std::shared_ptr<PumpHandle>>)>;

class Connector {
public:
    virtual ~Connector() = default;
    /// Opens a byte stream to `url` and starts a pump that drives `logic` on `strand` (an executor
    /// that serialises work). `done` gets the pump before any byte of `logic` is delivered.
    virtual void connect(boost::asio::any_io_executor strand, const ConnectionUrl& url, const ConnectOptions& options,
                         std::shared_ptr<ConnectionLogic> logic, ConnectHandler done) = 0;
};

/// What a listener says about an accepted byte stream.
struct AcceptedStream {
    /// Base URL of the listener the client reached, as the service index reports it (wire.md §11.2):
    /// `rr+tcp://<local address>:<port>/`, `rr+local:///`, …; empty when the transport cannot say.
    std::string local_url;
    /// The peer, for logs (an address, "local", a USB device path).
    std::string peer;
    /// The Cookie header of the WebSocket upgrade that carried this stream (rr+ws from a browser), or
    /// "": services may accept a web login made on the gateway's page (HostedService::authenticate_web).
    std::string web_login;
    /// Kept alive as long as the connection runs (its place in the per-address connection count,
    /// AddressLimiter::Slot; docs/security.md "Connection limits"); may be null.
    std::shared_ptr<const void> hold;
};

/// Where listeners hand accepted streams (implemented by the node). Thread-safe.
class ConnectionSink {
public:
    virtual ~ConnectionSink() = default;
    /// The logic for a new connection, or nullptr to refuse it (over the connection limit, shut down).
    virtual std::shared_ptr<ConnectionLogic> open_connection(const AcceptedStream& stream) = 0;
    /// Registers a running connection so that shutdown can close it.
    virtual void track(const std::shared_ptr<PumpHandle>& pump) = 0;
    /// False while new connections would be refused (limit reached): listeners then close a new
    /// socket without reading from it.
    virtual bool can_accept() const { return true; }
    /// The pacing of a new accepted connection's reads (messages/s, bytes/s), or nullptr: unpaced.
    virtual std::unique_ptr<ReadThrottle> make_read_throttle() { return nullptr; }
    /// A connection's reads were paused because it went over its rate (for metrics and the log).
    virtual void read_throttled(const std::string& peer) { (void)peer; }
};

/// Runs an accepted byte stream: asks `sink` for its logic (closing the stream when refused), then
/// starts a pump on the stream's executor, which must be a per-connection strand. `initial` holds
/// bytes already read while detecting the protocol. Returns false when refused.
template <class Stream>
bool serve_stream(ConnectionSink& sink, Stream stream, const AcceptedStream& info, std::vector<std::byte> initial = {}) {
    auto logic = sink.open_connection(info);
    if (!logic) {
        boost::system::error_code ignored;
        if constexpr (requires(Stream& s) { s.lowest_layer(); })
            stream.lowest_layer().close(ignored);
        else
            stream.close(ignored);
        return false;
    }
    typename StreamPump<Stream>::Strand strand(stream.get_executor());
    auto pump = std::make_shared<StreamPump<Stream>>(std::move(stream), strand, logic);
    pump->keep(info.hold);
    if (auto throttle = sink.make_read_throttle()) {
        // The sink (the node) outlives its pumps: it owns the io_context that runs them.
        pump->throttle(std::move(throttle), [s = &sink, peer = info.peer] { s->read_throttled(peer); });
    }
    logic->attach(pump);
    sink.track(pump);
    pump->start(initial);
    return true;
}

/// Starts a client pump over a connected stream and reports it (helper for connectors).
template <class Stream>
void start_client_stream(Stream stream, boost::asio::any_io_executor strand, std::shared_ptr<ConnectionLogic> logic,
                         const ConnectHandler& done) {
    auto pump = std::make_shared<StreamPump<Stream>>(std::move(stream), std::move(strand), logic);
    logic->attach(pump);
    done(std::shared_ptr<PumpHandle>(pump));
    pump->start();
}

/// The service half of a transport: accepts streams until stopped.
class Listener {
public:
    virtual ~Listener() = default;
    /// The URL scheme clients use for it ("rr+tcp", "rr+local", …).
    virtual std::string scheme() const = 0;
    /// Base URLs clients can reach it at (for discovery and the service index).
    virtual std::vector<std::string> urls() const = 0;
    /// Stops accepting (open connections stay). Idempotent; thread-safe.
    virtual void stop() = 0;
    /// The node's set of services changed and `service_state_nonce` is the node's new ServiceStateNonce
    /// (a listener that publishes one, as rr+local's entries do, writes it; Node::service_state_nonce()).
    virtual void services_changed(const std::string& service_state_nonce) { (void)service_state_nonce; }
};

}  // namespace rr::server
