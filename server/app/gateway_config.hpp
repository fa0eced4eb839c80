// rr-gateway configuration: one YAML file (schema in docs/gateway-config.md) plus command-line flags
// that override it. Validation is complete before anything starts: an error names the key and, for
// the file, its line; nothing starts half-configured.
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/discovery/service_filter.hpp"
#include "base/error/rr_error.hpp"
#include "server/gateway/device_mirror.hpp"
#include "server/record/recording_spec.hpp"

namespace rr::server::app {

/// `discovery:` (docs/gateway-config.md, docs/discovery.md): node discovery on the network. On by
/// default, as on an official server node (ServerNodeSetup): the gateway announces itself, answers
/// discovery requests and keeps a table of the nodes it hears.
struct DiscoverySettings {
    /// Off: no UDP at all (`--no-discovery`, `discovery.enabled: false`), e.g. a container on a network
    /// shared with strangers. `discover:` entries need it on.
    bool enabled = true;
    bool announce = true;          ///< announce the gateway (when enabled)
    bool ipv4_broadcast = false;   ///< also IPv4 broadcast (the official IPV4_BROADCAST flag)
    std::vector<std::string> interfaces;  ///< interface names; empty = all
    std::size_t max_nodes = 1024;  ///< node table cap (oldest evicted)
    std::chrono::milliseconds node_expiry{60000};  ///< a node's URL lives this long after its last announce
    /// Also list the rr+local nodes of this computer (their node directories, watched) in the table.
    bool local = true;
};

/// One `usb.allow` entry: a device admitted without the RR BOS capability (docs/usb.md).
struct UsbAllowEntry {
    std::uint16_t vendor_id = 0;
    std::uint16_t product_id = 0;
    std::uint8_t interface_number = 0;
};

/// `usb:` (docs/gateway-config.md, docs/usb.md): the rr+usb host transport (libusb).
struct UsbSettings {
    enum class Mode { automatic, on, off };
    /// automatic (the default): on when a device URL or a `discover:` entry's `transports` names
    /// rr+usb; on: always (USB devices then also appear in discovery); off: never (rr+usb URLs refused).
    Mode enabled = Mode::automatic;
    std::vector<UsbAllowEntry> allow;        ///< devices without the BOS capability
    bool hotplug = true;                     ///< libusb hotplug where available, else polling
    std::chrono::milliseconds poll_interval{2000};  ///< rescan period without hotplug
};

/// One `discover:` entry: services selected by filter become gateway devices while their node is seen.
struct DiscoverRule {
    rr::discovery::ServiceFilter filter;
    /// Device name; {service}, {nodename}, {nodeid} are replaced, then every character outside
    /// [A-Za-z0-9_] becomes '_' (RR service names).
    std::string name_template = "{service}";
    std::string username, password;
    std::chrono::milliseconds backoff_max{30000};
};

/// gateway.tls (docs/security.md): PEM files; TLS is on when `certificate` is set.
struct GatewayTlsConfig {
    std::string certificate;  ///< chain, leaf first
    std::string private_key;
    std::string client_ca;    ///< "" = no client certificates; else required (mTLS)
    std::string node_certificate, node_private_key;  ///< rrs+tcp only; "" = the certificate above
    /// Refuse plain RR and plain HTTP on the port (TLS and STARTTLS only). rr+local is not affected.
    bool required = false;
    bool enabled() const noexcept { return !certificate.empty(); }
};

/// gateway.auth (docs/security.md "Gateway users and permissions"): the gateway's own logins and the
/// role → rule policy. Files are read by load_gateway_auth (gateway_auth_config.hpp).
struct GatewayAuthConfig {
    std::string users;   ///< official password file; its privileges column holds each user's roles
    std::string tokens;  ///< opaque bearer tokens: `<token> <name> <roles>` per line
    struct Jwt {
        std::string algorithm;  ///< HS256, RS256, ES256; "" = no JWT
        std::string key;        ///< file: the HS256 secret, or the RS256/ES256 public key (PEM)
        std::string audience, issuer;
        std::string user_claim = "sub", roles_claim = "roles";
        unsigned leeway_s = 30;
    } jwt;
    struct Rule {
        std::vector<std::string> devices{"*"}, members{"*"};
        bool read = false, write = false, call = false, lock = false;
        bool record = false;  ///< recordings of the device (docs/recording.md)
    };
    std::vector<std::pair<std::string, std::vector<Rule>>> roles;
    unsigned max_failures = 5, window_s = 60, lockout_s = 300;
    unsigned session_ttl_s = 8 * 3600;
    /// Logins and permission checks are on.
    bool enabled() const noexcept { return !users.empty() || !tokens.empty() || !jwt.algorithm.empty(); }
};

/// Per-connection and per-address limits on the gateway's port (docs/security.md "Connection limits").
/// 0 = unlimited for each. Defaults: 256 connections per address (generous: no legitimate client, test
/// or benchmark comes near it); rates off (a legitimate wire or pipe stream has no natural ceiling).
struct GatewayLimitsConfig {
    /// Open connections (raw RR, WebSocket and HTTP alike) from one client IP address.
    std::size_t connections_per_address = 256;
    /// Messages per second one connection may send (RR messages, WebSocket frames, HTTP requests).
    std::uint64_t messages_per_second = 0;
    /// Bytes per second one connection may send.
    std::uint64_t bytes_per_second = 0;
    /// Burst: how many seconds of rate a connection may save up while idle (at least 1).
    unsigned burst_s = 1;
};

/// A `devices:` entry with `replay: FILE` instead of `url:` (docs/recording.md "Replay"): a device
/// whose source is an MCAP recording.
struct ReplayDeviceConfig {
    std::string name;  ///< device name ("" from --replay: the recorded device's name)
    std::string file;
    double speed = 1.0;  ///< playback speed factor (> 0)
    bool loop = false;   ///< start again at the end
    bool paused = false; ///< start paused (play from the API or the dashboard)
};

/// `safety:` (docs/gateway-config.md, docs/security.md "Motion safety"): the gateway as the dead-man
/// of the devices' motion. Gateway-wide settings, members of named devices, and per-device overrides
/// (`devices[].safety`).
struct SafetyConfig {
    std::chrono::milliseconds hold_to_run_max{500};  ///< hold_to_run_max_s (0.05 … 10 s)
    bool standard_robot = true;  ///< guard the standard robot's members where a device is one
    template <class T>
    struct ForDevice {
        std::string device;
        T rule;
    };
    std::vector<ForDevice<gateway::HoldToRunMember>> hold_to_run;
    std::vector<ForDevice<gateway::UntimedMotionMember>> motions;
    std::vector<ForDevice<std::string>> streams;
    std::vector<ForDevice<gateway::StopMember>> stops;
    struct Override {
        std::optional<std::chrono::milliseconds> hold_to_run_max;
        std::optional<bool> standard_robot;
    };
    std::map<std::string, Override> overrides;  ///< by device name (devices[].safety)

    /// The settings of device `name`: the gateway's, its override, and the members named for it.
    gateway::MotionSafety for_device(std::string_view name) const;
};

struct GatewayConfig {
    // gateway:
    /// Listen address. The default `::` is one dual-stack socket (IPv4 and IPv6, as an official node);
    /// on a host without IPv6 it falls back to `0.0.0.0`. `0.0.0.0`: IPv4 only; `127.0.0.1`: this computer.
    std::string listen = "::";
    std::uint16_t port = 8080;
    std::string node_name = "rr.gateway";
    std::string node_id;  ///< empty = random
    unsigned threads = 0;
    std::string web_root;  ///< empty = the built-in default (web/ next to the executable's project)
    /// Browser Origins allowed besides the same origin: "https://lab.example.org", "https://*.example.org",
    /// "https://" (any https origin), "*"; validated by the parser. Empty = same-origin only.
    std::vector<std::string> allowed_origins;
    /// Connections per client address, messages/s and bytes/s per connection.
    GatewayLimitsConfig limits;
    /// Reverse proxies whose X-Forwarded-For/-Proto are believed: addresses or CIDR ranges
    /// ("127.0.0.1", "10.0.0.0/8", "::1"); validated by the parser. Empty = none (the headers are ignored).
    std::vector<std::string> trusted_proxies;
    /// permessage-deflate (RFC 7692) for JSON WebSockets whose client offers it: `enabled` for every
    /// upgrade on the listener, else only for request paths under one of `paths` (docs/gateway-config.md).
    /// Off by default; binary messages (binary pushes, images) are never compressed.
    struct WebSocketCompression {
        bool enabled = false;
        std::vector<std::string> paths;
    } websocket_compression;
    /// Gathered writes on JSON WebSockets (issue 56): the messages waiting for one client leave in one
    /// kernel write (http::HttpOptions::websocket_gathered_writes). On by default; false writes each
    /// message with its own asynchronous write (the A/B switch of bench/run.py --only gather).
    bool websocket_gathered_writes = true;
    std::size_t max_message_size = 12u * 1024u * 1024u;
    std::string log_level = "info";
    /// "text" (one line per message) or "json" (one object per line: time, level, message, device,
    /// client, request); docs/deployment.md §Logs.
    std::string log_format = "text";
    /// Serve rr+local under node_name (and the demo node's under node_name + ".demo"), so clients on
    /// this computer reach the gateway by NodeName without TCP (docs/local-transport.md).
    bool local = true;
    /// HTTPS, WSS, RR over TLS and rrs+tcp on the same port.
    GatewayTlsConfig tls;
    /// Logins and per-member permissions (auth: gateway).
    GatewayAuthConfig auth;
    // demo:
    bool demo = true;
    std::uint16_t demo_port = 0;  ///< RR port of the embedded demo devices' node (0 = ephemeral)
    // devices:
    std::vector<gateway::DeviceConfig> devices;
    // devices: entries with `replay:` (--replay FILE)
    std::vector<ReplayDeviceConfig> replays;
    // record: (docs/recording.md): recordings started when their device connects
    std::vector<record::RecordingSpec> record;
    // recordings: where recordings go and the bounds on them (docs/recording.md "Where recordings go")
    record::RecordingsSettings recordings;
    // foxglove: (docs/foxglove.md) objects below the root advertised to Foxglove clients, by device name
    std::map<std::string, std::vector<std::string>> foxglove_objects;
    /// foxglove.clock: the device whose DeviceClock is the Foxglove WebSocket's time ("" = a clock device).
    std::string foxglove_clock;
    // discovery: / discover:
    DiscoverySettings discovery;
    std::vector<DiscoverRule> discover;
    // usb:
    UsbSettings usb;
    // safety:
    SafetyConfig safety;
};

/// Whether the configuration needs the rr+usb host transport (UsbSettings::enabled).
bool usb_wanted(const GatewayConfig& config);

/// Parses YAML text. `source` names the file in error messages. Errors: InvalidConfiguration with
/// "<source>:<line>: <key>: <problem>".
Result<GatewayConfig> parse_gateway_config(std::string_view yaml_text, std::string_view source);

/// Reads and parses a file. Errors: as parse_gateway_config, or InvalidConfiguration when unreadable.
Result<GatewayConfig> load_gateway_config(const std::string& path);

/// What the command line asked for: a config file, overrides, and modes.
struct CommandLine {
    std::optional<std::string> config_file;
    bool help = false;
    bool check_only = false;  ///< --check: validate the configuration and exit
    /// Applies the overrides to `config`. Errors: InvalidConfiguration naming the flag.
    std::vector<std::string> overrides;  ///< raw flags, applied in order by apply_overrides
};

/// Splits argv into CommandLine. Unknown flags are errors (InvalidConfiguration "unknown flag …").
/// Accepted: --config FILE, --port N, --listen ADDR, --web-root DIR, --allow-origin ORIGIN (repeat),
/// --trusted-proxy ADDR[/BITS] (repeat),
/// --device NAME=URL (repeat), --replay FILE (repeat), --recordings-root DIR, --no-demo, --demo-port N, --threads N, --log-level LEVEL, --log-format text|json, --no-local,
/// --no-discovery, --discovery (the default; overrides a file's `discovery.enabled: false`), --check, --tls-certificate FILE, --tls-private-key FILE, --tls-client-ca FILE, --tls-required,
/// --help, and the official --robotraconteur-tcp-port=N, --robotraconteur-nodename=NAME,
/// --robotraconteur-nodeid=ID, --robotraconteur-log-level=LEVEL (both `--flag=value` and `--flag value`).
Result<CommandLine> parse_command_line(int argc, const char* const* argv);
Result<void> apply_overrides(GatewayConfig& config, const CommandLine& cmd);

/// Usage text for --help.
std::string usage_text();

}  // namespace rr::server::app
