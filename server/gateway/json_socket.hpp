// The WebSocket half of the JSON API (docs/json-api.md §WebSocket): subprotocol `rr-gateway.json.v1`
// on the gateway's HttpServer. Text messages, one JSON object each.
//
// Client → gateway: requests {"id", "op", …}; op ∈ login, device_login, device_logout, devices,
// device, get, set, call, peek, subscribe, unsubscribe, set_out_value, send. Each is answered once with {"id", "result"} or {"id", "error"}.
// Gateway → client, unasked: {"subscription", "kind": "wire"|"event"|"pipe"|"pipe_ack"|"closed", …} for
// subscriptions, and {"kind": "device_state", "device": {…}} whenever a device's state changes. A
// subscription made with "binary": true gets values with numeric arrays as binary messages
// (binary_push.hpp), rendered once per value for all such subscribers, as the text form is.
//
// Backpressure (a client that reads slowly never grows the gateway's memory without bound):
//   * the socket's own queue holds at most HttpOptions::json_socket_queue_limit messages (oldest dropped);
//   * wire values are coalesced per subscription: the newest value waits while `wire_queue_threshold`
//     messages or `wire_bytes_threshold` bytes are queued, and replaces an older waiting one (so a slow
//     reader of camera frames gets the newest frame, one or two frames behind, not a backlog);
//   * events and pipe packets are dropped (counted, and reported as "dropped" in the next push of that
//     subscription) while `push_queue_limit` messages or `push_bytes_limit` bytes are queued;
//   * pipe packets become JSON on one strand shared by all sockets, never on the device connection's
//     strand: a slow conversion (a camera frame) delays neither the device's replies nor other
//     traffic, and takes at most one worker thread; a socket's packets are dropped (counted) while
//     `max_pipe_conversions` of its own, or `max_pipe_conversion_bytes` of their payload, wait there;
//   * a subscription made with "max_rate_hz" gets at most one value per window of 1/max_rate_hz, the
//     windows on one grid for all sockets (rate_window.hpp): the subscriptions of one wire at one rate
//     form a rate group (wire_rate_groups.hpp) that is offered each device value once and hands its
//     newest to them at each window; a pipe's packets wait in a queue of "queue_length" (oldest
//     dropped, counted), woken by one timer per rate (rate_ticker.hpp);
//   * replies are never dropped by this layer; at most `max_in_flight` requests per socket are being
//     answered at once, and messages over `max_message_bytes` are refused.
// Subscriptions end when the socket closes (wires/events unsubscribed, pipe endpoints disconnected).
//
// The parts, each testable without a socket: json_socket_request.hpp (messages into typed requests,
// the op table), json_subscriptions.hpp (the registry and its push policy), json_push.hpp (push bodies).
#pragma once

#include <chrono>
#include <memory>
#include <mutex>
#include <vector>

#include <boost/asio/any_io_executor.hpp>
#include <boost/asio/strand.hpp>

#include "server/gateway/conversion_budget.hpp"
#include "server/gateway/json_api.hpp"
#include "server/http/http_server.hpp"

namespace rr::server::gateway {

inline constexpr std::string_view kJsonSubprotocol = "rr-gateway.json.v1";

/// Where pipe packets become JSON (see above).
using ConvertStrand = boost::asio::strand<boost::asio::any_io_executor>;

struct JsonSocketOptions {
    std::size_t push_queue_limit = 768;             ///< messages queued: events / pipe packets dropped from here
    std::size_t push_bytes_limit = 8u << 20;        ///< bytes queued: pushes dropped / wire values wait from here
    std::size_t wire_queue_threshold = 8;           ///< messages queued: wire values wait (coalesced) from here
    std::size_t wire_bytes_threshold = 1u << 20;    ///< bytes queued: wire values wait (coalesced) from here
    std::size_t max_pipe_conversions = 16;          ///< a socket's pipe packets waiting for their JSON: newer dropped (a burst of small packets must fit)
    std::size_t max_pipe_conversion_bytes = 4u << 20;  ///< and their payload bytes (one larger packet alone still goes)
    std::chrono::milliseconds wire_retry{10};       ///< how often waiting wire values retry
    std::size_t max_in_flight = 64;                 ///< requests per socket being answered at once
    std::size_t max_subscriptions = 256;            ///< per socket
    std::size_t max_message_bytes = 1u << 20;       ///< largest request message
};

/// What one socket holds, for tests and diagnostics.
struct JsonSocketStats {
    std::size_t subscriptions = 0;
    std::size_t queued = 0, queued_bytes = 0;  ///< the socket's queue now
    std::uint64_t socket_dropped = 0;          ///< dropped by the socket's queue limit
    std::uint64_t push_drops = 0;              ///< events / pipe packets dropped by this layer
    std::uint64_t wire_coalesced = 0;          ///< wire values replaced by a newer one before sending
    std::size_t pending_wires = 0;             ///< subscriptions with a wire value (or rate-limited pipe packets) waiting
};

class JsonSocketSession;
class RateTicker;
class WireRateGroups;

/// Serves the subprotocol: one JsonSocketSession per socket.
class JsonSocketServer : public std::enable_shared_from_this<JsonSocketServer> {
public:
    /// `executor` runs the wire retry timers and the pipe packets' JSON conversion (the gateway
    /// node's io_context).
    static std::shared_ptr<JsonSocketServer> create(std::shared_ptr<JsonApi> api, boost::asio::any_io_executor executor,
                                                    JsonSocketOptions options = {});
    ~JsonSocketServer();

    /// The handler to register with HttpServer::add_subprotocol(kJsonSubprotocol, …).
    http::JsonSocketHandler handler();
    /// One entry per open socket.
    std::vector<JsonSocketStats> stats() const;
    const JsonSocketOptions& options() const noexcept { return options_; }
    /// Rate groups now: rate-limited wires' distinct (wire, max_rate_hz) pairs (wire_rate_groups.hpp).
    std::size_t rate_groups() const;

private:
    JsonSocketServer(std::shared_ptr<JsonApi> api, boost::asio::any_io_executor executor, JsonSocketOptions options);
    void on_open(const std::shared_ptr<http::JsonSocket>& socket);
    void on_message(const std::shared_ptr<http::JsonSocket>& socket, std::string text);
    void on_close(const std::shared_ptr<http::JsonSocket>& socket);
    void on_device_state(const DeviceStatus& status);
    void on_devices_changed(const std::shared_ptr<DeviceMirror>& device, bool added);
    void push_text(const nlohmann::json& message);

    std::shared_ptr<JsonApi> api_;
    boost::asio::any_io_executor executor_;
    ConvertStrand convert_strand_;
    std::shared_ptr<RateTicker> ticker_;  // one timer per rate for all sockets (rate_ticker.hpp)
    std::shared_ptr<WireRateGroups> groups_;  // rate-limited wires: one value per wire and rate (wire_rate_groups.hpp)
    JsonSocketOptions options_;
    std::vector<std::pair<std::shared_ptr<DeviceMirror>, std::uint64_t>> listeners_;
    mutable std::mutex mutex_;
    std::map<const http::JsonSocket*, std::shared_ptr<JsonSocketSession>> sessions_;
    std::uint64_t devices_listener_ = 0;
};

/// Registers the subprotocol on `http`; returns the server (kept alive by the registered handler too).
std::shared_ptr<JsonSocketServer> install_json_socket(http::HttpServer& http, std::shared_ptr<JsonApi> api,
                                                      JsonSocketOptions options = {});

}  // namespace rr::server::gateway
