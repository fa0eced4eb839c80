// The HTTP side of the gateway's single port (DESIGN: server/http): sockets whose first bytes are not
// `RRAC` come here, plain (handle) or after a TLS handshake (handle_tls: HTTPS, WSS). Serves registered routes (JSON API, /livez, /readyz, /metrics), static files, and
// WebSocket upgrades:
//   * subprotocol `robotraconteur.robotraconteur.com` (or none): raw RR over binary frames, served by the
//     node exactly like a TCP connection (wire.md §8) — what `rr+ws://host:port/?service=…` clients use;
//     without a subprotocol, a first message in a text frame (a JSON client that forgot its subprotocol)
//     gets one text message {"error": {"name": "RobotRaconteur.ProtocolError", "message": …}} naming
//     the registered subprotocols, then a close (1008, policy) with the same hint as its reason;
//   * other registered subprotocols (the JSON WebSocket API): handed to their handler;
//   * any other subprotocol list: 426 naming the subprotocols served.
// Origins: a request carrying an Origin header must be same-origin (its Host) or match the allowlist
// (403 otherwise); requests without Origin (non-browser clients) are allowed. Behind a trusted proxy
// (HttpOptions::trusted_proxies) the client's address comes from X-Forwarded-For and the same-origin
// check uses the X-Forwarded-Proto scheme; from any other peer those headers are ignored. Matching follows CORE (wire.md §8): exact, or
// `scheme://host[:port]` prefix, `scheme://` for any origin of that scheme, `scheme://*.domain`.
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <boost/asio/ip/tcp.hpp>
#include "server/http/forwarded.hpp"
#include <boost/beast/http/message.hpp>
#include <boost/beast/http/string_body.hpp>

#include "server/transport/tcp_listener.hpp"
#include "server/transport/tls/tls_stream_fwd.hpp"

namespace rr::server {

class Node;

namespace http {

using Request = boost::beast::http::request<boost::beast::http::string_body>;
using Response = boost::beast::http::response<boost::beast::http::string_body>;
/// Set by the server on every request a route handler sees (a value the client sent under these names
/// is removed first): the client's address ("ip:port"; behind a trusted proxy the proxy's client), and
/// "1" when the request came over TLS (or, behind a trusted proxy, X-Forwarded-Proto was https).
inline constexpr std::string_view kClientAddressField = "X-RR-Gateway-Client";
inline constexpr std::string_view kSecureField = "X-RR-Gateway-Secure";
/// Route handlers answer through `respond`, from any thread, exactly once.
using Responder = std::function<void(Response)>;
using RouteHandler = std::function<void(const Request& request, Responder respond)>;

/// The connection a request came on, for a handler whose work must end with its client (the
/// gateway's motion safety: a motion a request started ends when the request's connection closes).
class RequestConnection {
public:
    virtual ~RequestConnection() = default;
    /// Calls `gone` once, from the connection's strand, when the client closes the connection (or it
    /// fails) before the request is answered; never once it is answered. A later call replaces `gone`.
    /// Thread-safe. Plain HTTP has no round trip while the client waits: a connection that stops
    /// forwarding without closing (a black-holed proxy) is not noticed (docs/security.md).
    virtual void on_gone(std::function<void()> gone) = 0;
};
using WatchedRouteHandler =
    std::function<void(const Request& request, Responder respond, const std::shared_ptr<RequestConnection>& connection)>;

/// A WebSocket session for a non-RR subprotocol: `send` queues a text message (thread-safe), `close`
/// ends the session. The handler gets messages through on_message and on_close.
class JsonSocket {
public:
    virtual ~JsonSocket() = default;
    virtual void send(std::string text) = 0;
    /// Queues `text` ahead of the messages sent with send() that are still waiting (after the one being
    /// written and after earlier send_urgent() messages, which keep their order): answers to the
    /// client's requests do not wait behind a backlog of pushes. Thread-safe.
    virtual void send_urgent(std::string text) { send(std::move(text)); }
    /// Queues `bytes` as one binary message (the gateway's binary pushes), in order with send() and
    /// under the same queue limit. Thread-safe.
    virtual void send_binary(std::string bytes) = 0;
    /// Queues one binary message made of `head` and then `tail`; `tail` is shared, not copied (the
    /// same arrays go to every subscriber of a value). Thread-safe.
    virtual void send_binary(std::string head, std::shared_ptr<const std::string> tail) {
        head.append(*tail);
        send_binary(std::move(head));
    }
    /// Queues one text message made of `head` and then `body` from `body_offset` on (at most its
    /// size); `body` is shared, not copied (a push's body, the same for every subscriber of a value),
    /// and `head` is copied (inline when short: no allocation). In order with send(). Thread-safe.
    virtual void send_shared(std::string_view head, std::shared_ptr<const std::string> body, std::size_t body_offset) {
        std::string text(head);
        text.append(*body, std::min(body_offset, body->size()));
        send(std::move(text));
    }
    virtual void close() = 0;
    /// close() because the server is stopping: the close frame says 1001 Going Away (a client that
    /// reconnects can tell a restart from a network failure, which it sees as 1006).
    virtual void close_going_away() { close(); }
    /// Remote address, for logs.
    virtual std::string peer() const = 0;
    /// The Cookie header of the upgrade request ("" without one), for handlers that authenticate the
    /// socket by a session cookie.
    virtual std::string cookie_header() const { return {}; }
    /// The upgrade request's target (path and query, e.g. `/foxglove?token=…`), for handlers that
    /// serve one path or read a login from the query (browsers cannot set headers on a WebSocket).
    virtual std::string request_target() const { return {}; }
    /// The subprotocol the upgrade chose (one of the handler's names).
    virtual std::string subprotocol() const { return {}; }
    /// Messages accepted by send() (and send_binary()) and not yet written (the one being written included), and
    /// their bytes: for backpressure decisions by the handler. Thread-safe.
    virtual std::size_t queued() const { return 0; }
    virtual std::size_t queued_bytes() const { return 0; }
    /// Messages dropped because the queue was full (HttpOptions::json_socket_queue_limit).
    virtual std::uint64_t dropped() const { return 0; }
    /// Writes handed to the kernel (or the TLS layer) for this socket's messages and control frames,
    /// since it opened (HttpOptions::websocket_gathered_writes: fewer than the messages when several
    /// waited together). Thread-safe; for tests and diagnostics.
    virtual std::uint64_t writes() const { return 0; }
    /// Probes the client (the gateway while it holds a motion without a timeout of its own): a ping every
    /// `timeout` / 5, and the socket ends (on_close) when no frame at all, pong or message, arrives for
    /// `timeout`. nullopt: off. Thread-safe.
    virtual void set_liveness_probe(std::optional<std::chrono::milliseconds> timeout) {}
};
struct JsonSocketHandler {
    std::function<void(std::shared_ptr<JsonSocket>)> on_open;
    std::function<void(const std::shared_ptr<JsonSocket>&, std::string text)> on_message;
    std::function<void(const std::shared_ptr<JsonSocket>&)> on_close;
    /// Binary messages from the client; unset: they go to on_message like text (the JSON API).
    std::function<void(const std::shared_ptr<JsonSocket>&, std::string bytes)> on_binary;
};

struct HttpOptions {
    /// Origins allowed for browser requests (see above). Empty = no browser origin allowed.
    std::vector<std::string> allowed_origins;
    /// Folder served for GET requests that match no route ("" = none). index.html for directories.
    std::string static_root;
    /// Largest request body, bytes.
    std::size_t max_body_bytes = 1u << 20;
    /// Time allowed for reading one request, ms.
    std::chrono::milliseconds read_timeout{30000};
    /// Text messages queued for one JSON WebSocket beyond this are dropped oldest-first (send() messages
    /// before send_urgent() ones) and counted. The limit holds for the socket's write queue and for the
    /// messages sent but not yet taken by its strand, each: queued() is at most twice this.
    std::size_t json_socket_queue_limit = 1024;
    /// Peers whose X-Forwarded-For / X-Forwarded-Proto are believed (forwarded.hpp). Empty = none.
    std::vector<IpNetwork> trusted_proxies;
    /// permessage-deflate (RFC 7692) for JSON-subprotocol WebSockets whose client offers it: on every
    /// upgrade, or (false) only on those whose request path is one of `websocket_deflate_paths` or
    /// below one. Never for raw RR WebSockets; binary messages are never compressed.
    bool websocket_deflate = false;
    std::vector<std::string> websocket_deflate_paths;
    /// Gathered writes on JSON-subprotocol WebSockets (issue 56): every message waiting for one socket
    /// (up to 64 KiB of them, each of at most 16 KiB) is framed by Beast into one buffer and handed to
    /// the kernel with one non-blocking write, instead of one asynchronous write per message (gather_stream.hpp).
    bool websocket_gathered_writes = true;
    /// Called once per accepted WebSocket with a line for the log: kind, client, and the proxy when the
    /// client came through a trusted one (`WebSocket rr from 198.51.100.1 (https, via 10.0.0.1:5123)`).
    std::function<void(const std::string&)> on_websocket;
    /// Called after each HTTP response is queued (not for WebSocket upgrades): the client's address
    /// ("ip:port"), the request line ("GET /livez"; "" when the request could not be parsed) and the
    /// status code. On the connection's thread: keep it short (the gateway's access log).
    std::function<void(std::string_view client, std::string_view request, unsigned status)> on_response;
};

bool origin_allowed(const std::vector<std::string>& allowlist, std::string_view origin);
/// Whether a WebSocket upgrade for request `target` ("/path?query") may negotiate permessage-deflate
/// (HttpOptions::websocket_deflate, websocket_deflate_paths: a path matches itself and what is below it).
bool websocket_deflate_allowed(const HttpOptions& options, std::string_view target);
/// True when `origin` is "http://" or "https://" followed by the request's Host header: a page served
/// by this server (also behind a reverse proxy that forwards Host). Always allowed.
/// With `scheme` ("http"/"https", from a trusted proxy's X-Forwarded-Proto) only that scheme matches.
bool same_origin(std::string_view origin, std::string_view host, std::string_view scheme = {});

class HttpServer : public std::enable_shared_from_this<HttpServer> {
public:
    HttpServer(std::weak_ptr<Node> node, HttpOptions options);

    /// Entry point for a TCP port's non-RR sockets (TcpListenerOptions::http; see http_handler()).
    /// `hold` is kept alive as long as the connection runs, upgrades included (AcceptedStream::hold).
    void handle(boost::asio::ip::tcp::socket socket, std::vector<std::byte> initial, std::shared_ptr<const void> hold = {});
    /// Entry point for TLS connections (TlsListenOptions::https; see https_handler()): HTTPS requests and WSS upgrades,
    /// served exactly as their plain counterparts (http_server_tls.cpp).
    void handle_tls(TlsStream stream, std::vector<std::byte> initial, std::shared_ptr<const void> hold = {});

    /// Exact-path route for a method (GET, POST, PUT…); `prefix` routes match a path prefix.
    void add_route(boost::beast::http::verb method, std::string path, RouteHandler handler, bool prefix = false);
    /// A route for every method, also ones Beast does not know (the handler answers 405 itself).
    void add_route_any_method(std::string path, RouteHandler handler, bool prefix = false);
    /// A route whose handler also gets the request's connection (RequestConnection).
    void add_watched_route(boost::beast::http::verb method, std::string path, WatchedRouteHandler handler, bool prefix = false);
    /// WebSocket subprotocol served by a JSON handler.
    void add_subprotocol(std::string name, JsonSocketHandler handler);

    const HttpOptions& options() const noexcept { return options_; }

    // Used by sessions.
    /// The route for `method` and `path`: routes of that method first, then (with `any_method`) routes
    /// for any method, each in the order added.
    const WatchedRouteHandler* find_route(boost::beast::http::verb method, std::string_view path, bool any_method = true) const;
    const JsonSocketHandler* find_subprotocol(std::string_view name) const;
    /// The registered JSON subprotocols, comma-separated (for error messages).
    std::string subprotocol_names() const;
    std::shared_ptr<Node> node() const { return node_.lock(); }
    /// A JSON WebSocket session that has started: go_away() closes it. A session started after
    /// go_away() is closed at once. Thread-safe.
    void track_socket(const std::shared_ptr<JsonSocket>& socket);
    /// The server is stopping: every JSON WebSocket (the JSON API's, Foxglove's) is closed with 1001
    /// Going Away. Returns at once; the close handshakes run on the sockets' threads. Thread-safe.
    void go_away();

private:
    std::mutex sockets_mutex_;
    std::vector<std::weak_ptr<JsonSocket>> sockets_;  // under sockets_mutex_; expired ones pruned as it grows
    bool going_away_ = false;                         // under sockets_mutex_
    std::weak_ptr<Node> node_;
    HttpOptions options_;
    struct Route {
        std::optional<boost::beast::http::verb> method;  ///< none: any method
        std::string path;
        bool prefix;
        WatchedRouteHandler handler;  // a RouteHandler's ignores the connection
    };
    std::vector<Route> routes_;
    std::map<std::string, JsonSocketHandler, std::less<>> subprotocols_;
};

/// A plain response with the given status, content type and body (keep-alive copied from `request`).
Response make_response(const Request& request, boost::beast::http::status status, std::string body,
                       std::string_view content_type = "text/plain; charset=utf-8");

/// The TcpListenerOptions::http hook that hands a port's non-RR sockets to `server`, held weakly (once
/// it is gone they are closed).
HttpHandler http_handler(std::weak_ptr<HttpServer> server);
/// The TlsListenOptions::https hook, the same for TLS connections that are not RR (HTTPS, WSS).
HttpsHandler https_handler(std::weak_ptr<HttpServer> server);

}  // namespace http
}  // namespace rr::server
