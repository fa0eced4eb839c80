// A device behind the gateway (DESIGN "The gateway model"): one upstream client session to the device,
// kept alive with reconnects and exponential backoff, and a MirrorService that re-hosts the device's
// root object on the gateway's node under the device's name.
//
// Forwarding is at the message-entry level: requests are re-addressed (service path, RequestID,
// endpoints) and their elements passed on without decoding values. Events and wires are subscribed
// once upstream and fanned out to every downstream client (wires keep only the newest value per
// client); pipes map each downstream endpoint to its own upstream endpoint; callbacks from the device
// go to the downstream client that most recently called into the device; generators are owned by the
// client that created them. A device that goes away fails pending requests with ConnectionError;
// downstream wire connections stay open and are re-subscribed when the device returns. Object and
// monitor locks of the clients are held by the mirror itself (ServiceLocks; they survive a device
// restart) and checked before a request is forwarded.
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include <boost/asio/steady_timer.hpp>

#include "base/names/connection_url.hpp"
#include "server/client/raw_client.hpp"
#include "server/gateway/motion_rules.hpp"
#include "server/gateway/passthrough_sessions.hpp"
#include "server/gateway/session_endpoints.hpp"
#include "server/gateway/shared_entry.hpp"
#include "server/node/service.hpp"

namespace rr::server {
class Node;
}

namespace rr::server::gateway {

/// How downstream clients' logins reach the device (docs/security.md).
enum class DeviceAuth : std::uint8_t {
    /// One upstream session (with `username`/`password` below) shared by every client; object and
    /// monitor locks are held at the gateway (they bind the gateway's clients, not the device's others).
    shared,
    /// Every native RR client gets its own upstream session with its own credentials
    /// (PassthroughSessions); the shared session still serves the JSON API and the definitions.
    passthrough,
};
std::string_view device_auth_name(DeviceAuth a) noexcept;

struct DeviceConfig {
    std::string name;  ///< service name on the gateway (a valid RR service name)
    std::string url;   ///< rr+tcp://host:port/?service=…
    std::string username, password;
    /// Log in with a gateway's bearer token or JWT (credentials {"token": …}, token_credentials) instead
    /// of `password`; `username` is then `<name>@token` or `<sub>@jwt`. Set by `rr record --token`
    /// (a device behind another gateway's logins); not a gateway config key.
    std::string token;
    /// rr+ws/rr+wss: the WebSocket handshake's Authorization header (a reverse proxy's basic auth,
    /// `rr record --http-login`); "" = none. Not a gateway config key.
    std::string http_authorization;
    /// rr+wss, rrs+tcp: PEM certificates to trust ("" = the system's), and the gateway's own
    /// certificate and key to present when the device requires client certificates ("" = none).
    std::string tls_ca, tls_certificate, tls_private_key;
    DeviceAuth auth = DeviceAuth::shared;
    /// auth: passthrough: upstream sessions at once (one per logged-in native client); more are refused.
    std::size_t max_passthrough_sessions = 64;
    /// auth: passthrough: JSON API member requests (REST, and the WebSocket without a `device_login`)
    /// are refused with AuthenticationError instead of using the gateway's own session to the device.
    bool json_api_requires_device_login = false;
    /// Motion safety (docs/security.md "Motion safety"): the bound of hold-to-run timeouts, streams and
    /// liveness, and the members guarded besides the standard robot's.
    MotionSafety safety;
    /// /readyz waits for required devices only.
    bool required = true;
    std::chrono::milliseconds backoff_initial{500};
    std::chrono::milliseconds backoff_max{30000};
};

enum class DeviceState : std::uint8_t { connecting, connected, failed };
std::string_view device_state_name(DeviceState s) noexcept;

/// Request latency histogram bucket bounds, seconds (Prometheus `le`).
inline constexpr double kLatencyBuckets[] = {0.0005, 0.001, 0.0025, 0.005, 0.01, 0.025, 0.05, 0.1, 0.25, 0.5, 1, 2.5, 5, 10};

struct DeviceCounters {
    std::atomic<std::uint64_t> requests{0}, request_errors{0}, events{0}, wire_packets_in{0}, wire_packets_out{0},
        pipe_packets{0}, pipe_drops{0}, event_drops{0}, callbacks{0}, reconnects{0};
    std::atomic<std::uint64_t> latency_buckets[std::size(kLatencyBuckets) + 1]{};
    std::atomic<std::uint64_t> latency_sum_us{0};
    void observe_latency(std::chrono::steady_clock::duration d);
};

/// A snapshot for the JSON API and /metrics.
struct DeviceStatus {
    std::string name, url;
    DeviceState state = DeviceState::connecting;
    std::string reason;  ///< why it failed / last error
    std::string object_type;
    bool required = true;
    std::size_t downstream_sessions = 0;
    DeviceAuth auth = DeviceAuth::shared;
    std::size_t upstream_sessions = 0;   ///< passthrough sessions open (or opening) to the device
    bool json_api_requires_device_login = false;
    std::vector<DeviceLockInfo> locks;   ///< locks taken through the gateway (passthrough) or held at it (shared)
};

class MirrorService;
class MotionGuard;

class DeviceMirror : public std::enable_shared_from_this<DeviceMirror> {
public:
    /// Validates the config (name, URL). Errors: InvalidConfiguration naming the field.
    static Result<std::shared_ptr<DeviceMirror>> create(std::shared_ptr<Node> node, DeviceConfig config);
    ~DeviceMirror();

    /// Starts connecting (and keeps reconnecting until stop()).
    void start();
    void stop();

    DeviceStatus status() const;
    const DeviceConfig& config() const noexcept { return config_; }
    const DeviceCounters& counters() const noexcept { return *counters_; }
    /// The device's service definition texts (root first), empty before the first connect.
    std::vector<std::string> service_definitions() const;
    std::string object_type() const;
    /// The root object's type and the types it implements, as the device said at connect; empty before.
    ObjectTypeInfo root_type() const;
    /// The device's service attributes (a dictionary element; of another type before the first connect).
    MessageElement attributes() const;
    /// The upstream session when connected (for the JSON API), else nullptr.
    std::shared_ptr<RawClient> upstream() const;

    /// Sends a request to the device on behalf of the gateway itself (JSON API). The entry's service
    /// path uses the gateway's name for the device; the reply's is rewritten back the same way.
    void request(MessageEntry entry, std::function<void(Result<MessageEntry>)> done);
    /// The same on a JSON API client's own session (open_api_session); `session` 0 = the shared one.
    void request(MessageEntry entry, std::function<void(Result<MessageEntry>)> done, std::uint32_t session);

    /// request() for a stop (docs/security.md "Motion safety"): on a passthrough device a refusal for a
    /// lock another client took through the gateway sends it again on that client's session.
    void request_stop(MessageEntry entry, std::function<void(Result<MessageEntry>)> done, std::uint32_t session);

    /// A JSON API client's own session to a passthrough device: its id for request() and
    /// close_api_session(), and its event, wire and pipe subscriptions.
    struct ApiSession {
        std::uint32_t id = 0;
        std::shared_ptr<SessionEndpoints> endpoints;
    };
    /// auth: passthrough: opens an upstream session of the device's own, logged in as `username` with
    /// {"password": password}, for a JSON API client (the `device_login` op, docs/json-api.md); it counts
    /// against max_passthrough_sessions. `done` gets the session, or the error: InvalidOperation on a
    /// shared device, the device's own (AuthenticationError …), ConnectionError, BufferLimitViolation
    /// over the session limit.
    void open_api_session(std::string username, std::string password, std::function<void(Result<ApiSession>)> done);
    /// Closes it (the device releases its client locks and monitors). Unknown ids are ignored.
    void close_api_session(std::uint32_t session);
    /// Subscribes the gateway itself to a wire or event (JSON API): `on_entry` gets upstream WirePacket /
    /// EventReq entries for that member (paths in gateway naming), one SharedEntry per value shared by
    /// every subscriber. Returns an id for unsubscribe().
    std::uint64_t subscribe(std::string path, std::string member, bool is_wire,
                            std::function<void(const SharedEntryPtr&)> on_entry,
                            std::function<void(Result<void>)> done);
    void unsubscribe(std::uint64_t id);

    /// Called (from any thread, without locks held) whenever the state changes; for logs and pushes.
    void set_state_listener(std::function<void(const DeviceStatus&)> listener);
    /// More listeners beside that one (the JSON API's pushes); same calling rules. Returns an id for
    /// remove_state_listener.
    std::uint64_t add_state_listener(std::function<void(const DeviceStatus&)> listener);
    void remove_state_listener(std::uint64_t id);

    /// The downstream half (for the JSON API's gateway-internal pipe endpoints).
    const std::shared_ptr<MirrorService>& mirror_service() const noexcept { return service_; }
    /// The device's motion guard (motion_guard.hpp), used by every path a request takes to it.
    const std::shared_ptr<MotionGuard>& motion() const noexcept { return motion_; }

private:
    DeviceMirror(std::shared_ptr<Node> node, DeviceConfig config, ConnectionUrl url);
    void connect();
    RawClientOptions upstream_options(Node& node) const;
    void on_connected(std::shared_ptr<RawClient> client);
    void on_disconnected(const RRError& error);
    void schedule_reconnect();
    void on_upstream_entry(MessageEntry&& entry);
    void notify_state();

    std::weak_ptr<Node> node_;
    DeviceConfig config_;
    ConnectionUrl url_;
    std::shared_ptr<MirrorService> service_;
    std::shared_ptr<MotionGuard> motion_;
    boost::asio::steady_timer timer_;
    const std::shared_ptr<DeviceCounters> counters_ = std::make_shared<DeviceCounters>();  // shared with service_

    mutable std::mutex mutex_;
    DeviceState state_ = DeviceState::connecting;
    std::string reason_;
    std::shared_ptr<RawClient> client_;
    std::vector<std::string> definitions_;
    std::string object_type_;
    std::vector<std::string> implements_;
    MessageElement attributes_;
    std::chrono::milliseconds backoff_;
    bool stopped_ = false;
    bool registered_ = false;
    std::uint64_t generation_ = 0;  // bumps on every (re)connect, so stale callbacks are ignored
    std::function<void(const DeviceStatus&)> state_listener_;
    std::map<std::uint64_t, std::function<void(const DeviceStatus&)>> extra_listeners_;
    std::uint64_t next_listener_id_ = 1;
};

}  // namespace rr::server::gateway
