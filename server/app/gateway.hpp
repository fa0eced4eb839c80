// The assembled gateway: the gateway node (RR + HTTP + WebSocket on one port), one DeviceMirror per
// configured device, the embedded demo devices on their own node (reached over rr+tcp on loopback, so
// the default path is the real path; behind a per-process login while gateway.auth is on), health
// endpoints and the JSON API. Transports for the devices: the node's TransportRegistry, plus rr+usb
// (a UsbHost) when the configuration needs it (usb_wanted).
// Discovery (on by default, as on an official server node) is fed by UDP, by the rr+local node
// directories and by the USB devices; the gateway and, unless gateway.auth is on, its demo node
// announce themselves.
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <vector>

#include "server/app/gateway_config.hpp"
#include "server/common/address_limiter.hpp"
#include "server/gateway/device_mirror.hpp"
#include "server/gateway/json_api.hpp"
#include "server/http/http_server.hpp"
#include "server/node/node.hpp"
#include "server/transport/tls/tls_context.hpp"
#include "server/discovery/node_discovery.hpp"
#include "server/record/recordings.hpp"
#include "server/record/replay_device.hpp"

namespace rr::server::app {

/// The login the demo node's services require while gateway.auth is on: one user with a password drawn
/// at random when the gateway starts, known only to this process (docs/security.md "The demo node").
/// Empty `username`: no login (gateway.auth off; the demo node stays open as documented).
struct DemoLogin {
    std::string username, password;
    bool required() const noexcept { return !username.empty(); }
};

/// Starts demo devices on `demo_node` (already listening on `port`) and returns how to reach them. When
/// `login.required()`, every service it registers must require that login (Gateway::start refuses to
/// start otherwise) and the returned devices must log in with it.
using DemoStarter = std::function<Result<std::vector<gateway::DeviceConfig>>(
    const std::shared_ptr<Node>& demo_node, std::uint16_t port, const DemoLogin& login)>;
/// Adds routes and subprotocols (the JSON API) once the devices exist, and returns the JsonApi it
/// installed (or nullptr), so that discovered devices and the discovery routes reach it
/// (gateway::install_json_api is one).
using ApiInstaller = std::function<std::shared_ptr<gateway::JsonApi>(
    http::HttpServer& http, const std::vector<std::shared_ptr<gateway::DeviceMirror>>& devices,
    std::shared_ptr<gateway::auth::GatewayAuth> auth)>;

class DiscoveredDevices;
}  // namespace rr::server::app
namespace rr::server::discovery {
class LocalDiscoverySource;
}
namespace rr::server::foxglove {
class FoxgloveServer;
}
namespace rr::server::usb {
class UsbHost;
class UsbDiscoverySource;
}  // namespace rr::server::usb
namespace rr::server::app {

/// The TLS credentials of gateway.tls, loaded (every file checked). Errors: InvalidConfiguration
/// "gateway.tls: FILE: problem" (used by --check too).
Result<std::shared_ptr<TlsServerCredentials>> load_tls(const GatewayTlsConfig& tls);

class Gateway {
public:
    /// Starts everything or nothing. Errors: InvalidConfiguration, IOError (port in use, …).
    static Result<std::unique_ptr<Gateway>> start(GatewayConfig config, DemoStarter demo = {}, ApiInstaller api = {});
    ~Gateway();
    void stop();

    std::uint16_t port() const noexcept { return port_; }
    const GatewayConfig& config() const noexcept { return config_; }
    const std::shared_ptr<Node>& node() const noexcept { return node_; }
    const std::shared_ptr<Node>& demo_node() const noexcept { return demo_node_; }
    const std::vector<std::shared_ptr<gateway::DeviceMirror>>& devices() const noexcept { return devices_; }
    std::shared_ptr<gateway::DeviceMirror> device(std::string_view name) const;
    /// Node discovery (docs/discovery.md), nullptr when `discovery.enabled` is off.
    const std::shared_ptr<discovery::NodeDiscovery>& discovery() const noexcept { return discovery_; }
    /// The demo node's announces: nullptr unless discovery is on and the demo node is reachable from the
    /// network (the gateway listens on a wildcard address and gateway.auth is off).
    const std::shared_ptr<discovery::NodeDiscovery>& demo_discovery() const noexcept { return demo_discovery_; }
    /// Devices found by `discover:` filters or added from the JSON API, now.
    std::vector<std::shared_ptr<gateway::DeviceMirror>> discovered_devices() const;
    /// The rr+usb host transport, nullptr unless the configuration needs it (usb_wanted()).
    const std::shared_ptr<usb::UsbHost>& usb_host() const noexcept { return usb_host_; }
    /// USB devices found but unusable (no permission: the udev rule to install; malformed descriptors),
    /// for GET /api/discovered: [{"device": "1209:0001", "path": "/dev/bus/usb/…", "error": "…"}].
    nlohmann::json usb_problems() const;

    /// Ready when every required device is connected (/readyz).
    bool ready() const;
    /// TLS in use (gateway.tls), or nullptr.
    const std::shared_ptr<TlsServerCredentials>& tls() const noexcept { return tls_; }
    /// The gateway's users and permissions (gateway.auth), or nullptr when logins are off.
    const std::shared_ptr<gateway::auth::GatewayAuth>& auth() const noexcept { return auth_; }
    /// Reads the certificate files again (SIGHUP): new connections get the new certificate, open ones
    /// keep theirs. Errors (the old certificate stays): InvalidState without TLS, else as at start.
    Result<void> reload_tls();
    /// Prometheus text exposition of the gateway's counters (/metrics).
    std::string metrics_text() const;
    /// The recordings (docs/recording.md), nullptr without the JSON API.
    const std::shared_ptr<record::Recordings>& recordings() const noexcept { return recordings_; }
    /// The Foxglove WebSocket server (docs/foxglove.md); null without the JSON API.
    const std::shared_ptr<foxglove::FoxgloveServer>& foxglove() const noexcept { return foxglove_; }
    /// The replayed devices (`replay:` entries, --replay), served from replay_node().
    const std::vector<std::shared_ptr<record::ReplayDevice>>& replays() const noexcept { return replays_; }
    const std::shared_ptr<Node>& replay_node() const noexcept { return replay_node_; }

private:
    Gateway() = default;
    GatewayConfig config_;
    std::shared_ptr<Node> node_;
    /// gateway.limits.connections_per_address (null when 0 = unlimited).
    std::shared_ptr<AddressLimiter> address_limiter_;
    std::shared_ptr<Node> demo_node_;
    std::shared_ptr<http::HttpServer> http_;
    std::vector<std::shared_ptr<gateway::DeviceMirror>> devices_;
    std::shared_ptr<TlsServerCredentials> tls_;
    std::shared_ptr<gateway::auth::GatewayAuth> auth_;  // gateway.auth; null = logins off
    std::shared_ptr<std::atomic<std::uint64_t>> tls_failures_ = std::make_shared<std::atomic<std::uint64_t>>(0);
    std::uint16_t port_ = 0;
    /// The TCP port as bound (discovery announces it); written once before discovery starts.
    std::shared_ptr<boost::asio::ip::tcp::endpoint> tcp_bound_ = std::make_shared<boost::asio::ip::tcp::endpoint>();
    std::shared_ptr<discovery::NodeDiscovery> discovery_;
    /// The demo node's TCP port as bound, and its announces (null unless it is public and discovery on).
    std::shared_ptr<boost::asio::ip::tcp::endpoint> demo_bound_ = std::make_shared<boost::asio::ip::tcp::endpoint>();
    std::shared_ptr<discovery::NodeDiscovery> demo_discovery_;
    /// The demo node listens where the gateway does (a wildcard address) rather than on loopback only.
    bool demo_public_ = false;
    std::shared_ptr<DiscoveredDevices> discovered_;
    std::shared_ptr<usb::UsbHost> usb_host_;
    std::shared_ptr<discovery::LocalDiscoverySource> local_source_;
    std::shared_ptr<usb::UsbDiscoverySource> usb_source_;
    std::shared_ptr<record::Recordings> recordings_;
    std::shared_ptr<foxglove::FoxgloveServer> foxglove_;  // docs/foxglove.md
    /// Replayed devices live on a node of their own on loopback, mirrored like any device.
    std::shared_ptr<Node> replay_node_;
    std::vector<std::shared_ptr<record::ReplayDevice>> replays_;
};

}  // namespace rr::server::app
