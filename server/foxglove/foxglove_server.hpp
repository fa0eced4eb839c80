// The Foxglove WebSocket protocol on the gateway's port (docs/foxglove.md): subprotocols
// `foxglove.websocket.v1` and `foxglove.sdk.v1` on the HttpServer, at path /foxglove, behind the same
// TLS, Origin checks and logins as the JSON WebSocket. The protocol itself (messages, one
// connection's state, its bounds) is core/foxglove; this file meets it with the gateway's devices.
//
// What a client sees: serverInfo, then an advertise of every connected device's channels
// (foxglove_channels.hpp) and advertiseServices of its functions; unadvertise / advertise as devices
// disconnect and reconnect. Values come from the gateway's shared entries (DeviceMirror::subscribe):
// one rendering per wire value or event for every Foxglove and JSON WebSocket client. Rights as on
// the JSON WebSocket: read to subscribe and get parameters, write to set parameters and publish, call
// for services; a client publish to a wire passes the device's motion guard (hold-to-run and
// stream-silence rules) as set_out_value does.
//
// Backpressure (bounded per connection, FoxgloveOptions): the newest wire value per subscription
// waits while the socket is behind (older ones replaced and counted); events and pipe packets are
// dropped and counted while it is congested; pipe packets become JSON on one strand shared by all
// connections, at most max_pipe_conversions of a connection at a time.
#pragma once

#include <chrono>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <boost/asio/any_io_executor.hpp>

#include "core/foxglove/foxglove_session.hpp"
#include "server/foxglove/foxglove_channels.hpp"
#include "server/gateway/json_api.hpp"
#include "server/http/http_server.hpp"

namespace rr::server::foxglove {

inline constexpr std::string_view kFoxglovePath = "/foxglove";

struct FoxgloveOptions {
    /// Objects below the root advertised beside it, by device name (relative paths, e.g. `Webcams[0]`).
    std::map<std::string, std::vector<std::string>> objects;
    rr::foxglove::SessionLimits limits;
    std::size_t wire_queue_threshold = 8;        ///< socket messages queued: wire values wait (newest kept) from here
    std::size_t wire_bytes_threshold = 1u << 20; ///< socket bytes queued: the same
    std::size_t push_queue_limit = 256;          ///< socket messages queued: events / pipe packets dropped from here
    std::size_t push_bytes_limit = 8u << 20;     ///< socket bytes queued: the same
    std::size_t max_pipe_conversions = 16;       ///< a connection's pipe packets waiting for their JSON
    std::size_t max_pipe_conversion_bytes = 4u << 20;
    std::chrono::milliseconds wire_retry{10};    ///< how often waiting wire values retry
    std::size_t max_parameter_requests = 8;      ///< getParameters / setParameters being answered at once per connection
    /// The device whose clock is Foxglove's time (foxglove_clock.hpp); "" = a standard clock device, if any.
    std::string clock;
    std::chrono::milliseconds time_interval{20};  ///< at most one `time` message per this
};

/// One connection's counts, for tests and diagnostics.
struct FoxgloveStats {
    std::size_t subscriptions = 0, client_channels = 0;
    std::uint64_t messages_sent = 0;    ///< messageData frames
    std::uint64_t wire_coalesced = 0;   ///< wire values replaced by a newer one before sending
    std::uint64_t dropped = 0;          ///< events / pipe packets dropped while congested
    std::uint64_t statuses = 0;         ///< status messages (errors) sent
    std::uint64_t times_sent = 0;       ///< time messages
};

class FoxgloveConnection;
class FoxgloveClock;

class FoxgloveServer : public std::enable_shared_from_this<FoxgloveServer> {
public:
    static std::shared_ptr<FoxgloveServer> create(std::shared_ptr<gateway::JsonApi> api, boost::asio::any_io_executor executor,
                                                  FoxgloveOptions options = {});
    ~FoxgloveServer();

    /// The handler to register for both subprotocols.
    http::JsonSocketHandler handler();
    std::vector<FoxgloveStats> stats() const;

    // Used by connections.
    struct Catalog {
        std::vector<rr::foxglove::Channel> channels;
        std::vector<rr::foxglove::Service> services;
    };
    /// What is advertised now (every connected device's channels and services).
    Catalog catalog() const;
    /// The member behind a channel / service id, or a topic / parameter name; nullptr when gone.
    std::shared_ptr<const LiveMember> channel_member(std::uint32_t id) const;
    std::shared_ptr<const LiveMember> service_member(std::uint32_t id) const;
    std::shared_ptr<const LiveMember> member_named(const std::string& topic, LiveKind kind) const;
    /// Every readable property now.
    std::vector<std::shared_ptr<const LiveMember>> properties() const;
    const std::shared_ptr<gateway::JsonApi>& api() const noexcept { return api_; }
    const FoxgloveOptions& options() const noexcept { return options_; }
    const std::string& session_id() const noexcept { return session_id_; }
    /// A parameter's new value, to every connection subscribed to it.
    void parameter_changed(const rr::foxglove::Parameter& p);
    /// The clock followed for Foxglove's time (never null).
    const std::shared_ptr<FoxgloveClock>& clock() const noexcept { return clock_; }
    /// Whether a connection opened now gets the `time` capability: the configuration names a clock,
    /// or a standard clock device is followed.
    bool offers_time() const;

private:
    FoxgloveServer(std::shared_ptr<gateway::JsonApi> api, boost::asio::any_io_executor executor, FoxgloveOptions options);
    void watch(const std::shared_ptr<gateway::DeviceMirror>& device);
    void on_device_state(const std::shared_ptr<gateway::DeviceMirror>& device, const gateway::DeviceStatus& status);
    void device_up(const std::shared_ptr<gateway::DeviceMirror>& device);
    void device_down(const std::string& name);
    std::vector<std::shared_ptr<FoxgloveConnection>> connections() const;
    std::uint32_t id_for(const std::string& key, std::map<std::string, std::uint32_t>& ids, std::uint32_t& next);

    std::shared_ptr<gateway::JsonApi> api_;
    boost::asio::any_io_executor executor_;
    FoxgloveOptions options_;
    std::string session_id_;
    mutable std::mutex mutex_;
    struct DeviceEntry {
        std::vector<std::uint32_t> channel_ids, service_ids;
    };
    std::map<std::string, DeviceEntry> devices_;  // connected devices' advertised ids
    std::map<std::uint32_t, std::pair<rr::foxglove::Channel, std::shared_ptr<const LiveMember>>> channels_;
    std::map<std::uint32_t, std::pair<rr::foxglove::Service, std::shared_ptr<const LiveMember>>> services_;
    std::map<std::string, std::shared_ptr<const LiveMember>> properties_;  // by parameter name
    // Ids are kept per topic and schema, so a device that comes back gets the same ids (the spec allows
    // reuse only for the same topic, encoding and schema).
    std::map<std::string, std::uint32_t> channel_ids_, service_ids_;
    std::uint32_t next_channel_ = 1, next_service_ = 1;
    std::vector<std::pair<std::shared_ptr<gateway::DeviceMirror>, std::uint64_t>> listeners_;
    std::uint64_t devices_listener_ = 0;
    std::map<const http::JsonSocket*, std::shared_ptr<FoxgloveConnection>> connections_;
    boost::asio::strand<boost::asio::any_io_executor> convert_strand_;
    std::shared_ptr<FoxgloveClock> clock_;
};

/// Registers both subprotocols on `http`; returns the server (kept alive by the handlers too).
std::shared_ptr<FoxgloveServer> install_foxglove(http::HttpServer& http, std::shared_ptr<gateway::JsonApi> api,
                                                 FoxgloveOptions options = {});

}  // namespace rr::server::foxglove
