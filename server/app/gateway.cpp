#include "server/app/gateway.hpp"

#include "server/gateway/motion_guard.hpp"
#include "server/app/gateway_auth_config.hpp"
#include "server/record/replay_routes.hpp"
#include "server/foxglove/foxglove_server.hpp"
#include "server/gateway/mirror_service.hpp"

#include <cstdio>
#include <mutex>
#include <sstream>
#include <thread>

#include <openssl/crypto.h>
#include <openssl/rand.h>

#include "server/app/gateway_discovery.hpp"
#include "server/app/log.hpp"
#include "server/common/token_bucket.hpp"
#include "server/discovery/discovery_sources.hpp"
#include "server/transport/local/local_listener.hpp"
#ifdef RR_HAVE_USB
#include "server/discovery/usb_discovery.hpp"
#include "server/transport/usb/usb_host.hpp"
#endif
#include "server/transport/tcp_listener.hpp"
#include "server/transport/tls/tls_listener.hpp"

namespace rr::server::app {

namespace bhttp = boost::beast::http;

namespace {

std::string escape_label(std::string_view v) {
    std::string out;
    for (char c : v) {
        if (c == '\\' || c == '"') out += '\\';
        if (c == '\n') {
            out += "\\n";
            continue;
        }
        out += c;
    }
    return out;
}

// What to do about an rr+local setup error: another node holds the NodeName, or the node directories
// cannot be used (the systemd unit points them at its own folders).
std::string local_setup_fix(const RRError& e, const std::string& name) {
    const std::string off = "turn rr+local off (gateway.local: false, --no-local)";
    if (e.type == MessageErrorType::InvalidOperation)
        return " (another gateway or node with NodeName \"" + name +
               "\" runs on this computer: give this gateway another gateway.node_name (--robotraconteur-nodename) or " + off + ")";
    if (e.message.find("ROBOTRACONTEUR_USER_CONFIG_DIR") != std::string::npos) return " (or " + off + ")";
    return " (set ROBOTRACONTEUR_USER_CONFIG_DIR and ROBOTRACONTEUR_USER_RUN_DIR to writable folders, as the "
           "systemd unit does, or " + off + ")";
}

// The NodeName of a node that will serve rr+local, held for this process, and its NodeID from the
// NodeID cache (docs/local-transport.md). Errors name the fix.
Result<std::optional<local::NodeNameReservation>> reserve_local_name(bool local, const std::string& name,
                                                                     const NodeID& configured_id) {
    if (!local || name.empty()) return std::optional<local::NodeNameReservation>();
    auto r = local::reserve_node_name(local::default_node_directories(), name, configured_id);
    if (!r) return fail(r.error().type, "rr+local: " + r.error().message + local_setup_fix(r.error(), name));
    return std::optional<local::NodeNameReservation>(std::move(*r));
}

Result<void> serve_local(const std::shared_ptr<Node>& node, std::optional<local::NodeNameReservation> reservation) {
    auto l = local::listen_local(node, {}, std::move(reservation));
    if (!l) return fail(l.error().type, "rr+local: " + l.error().message + " (turn rr+local off with gateway.local: false, --no-local)");
    log(LogLevel::info, "rr+local: " + (*l)->url() +
                            (node->node_name().empty() ? std::string() : " (rr+local:///?nodename=" + node->node_name() + ")"));
    return {};
}

// Whether `listen` is a wildcard address (`::`, `0.0.0.0`): the node is reachable from the network.
bool listens_everywhere(const std::string& listen) {
    boost::system::error_code ec;
    const auto a = boost::asio::ip::make_address(listen, ec);
    return !ec && a.is_unspecified();
}

// Node discovery settings shared by the gateway's node and its demo node (docs/discovery.md).
discovery::DiscoveryOptions discovery_options(const DiscoverySettings& s, const std::shared_ptr<Node>& node,
                                              std::shared_ptr<boost::asio::ip::tcp::endpoint> bound) {
    discovery::DiscoveryOptions o;
    o.node_id = node->node_id();
    o.node_name = node->node_name();
    o.announce = s.announce;
    o.flags = rr::discovery::kLinkLocal | (s.ipv4_broadcast ? rr::discovery::kIpv4Broadcast : 0u);
    o.interfaces = s.interfaces;
    o.limits.max_nodes = s.max_nodes;
    o.limits.url_expiry = s.node_expiry;
    std::weak_ptr<Node> weak_node = node;
    // One ServiceStateNonce per node: the announces carry the node's, as its rr+local entries do.
    o.service_state_nonce = [weak_node] {
        auto n = weak_node.lock();
        return n ? n->service_state_nonce() : std::string();
    };
    // What the announces carry: the node's TCP port as bound (set before discovery starts).
    o.listen_endpoints = [bound = std::move(bound)] {
        std::vector<boost::asio::ip::tcp::endpoint> out;
        if (bound->port() != 0) out.push_back(*bound);
        return out;
    };
    return o;
}

// The demo node's one user while gateway.auth is on (docs/security.md "The demo node").
constexpr std::string_view kDemoUser = "rr-gateway-demo";

// A password for the demo node's user: 32 bytes from OpenSSL's CSPRNG as hex, drawn anew at each start
// and never written anywhere. No fallback: without randomness the gateway does not start.
Result<std::string> random_demo_password() {
    unsigned char raw[32];
    if (RAND_bytes(raw, sizeof raw) != 1)
        return fail(MessageErrorType::InternalError, "demo devices: no random bytes for the demo node's login (OpenSSL RAND_bytes)");
    static constexpr char kHex[] = "0123456789abcdef";
    std::string out;
    for (unsigned char b : raw) {
        out += kHex[b >> 4];
        out += kHex[b & 15];
    }
    OPENSSL_cleanse(raw, sizeof raw);
    return out;
}

// Warnings about a limit that bites, at most a burst of 5 then 1 per second: a flood of refused
// connections must not flood the log too. Lines held back are counted in the next one written.
class LimitLog {
public:
    void warn(const std::string& line) {
        std::uint64_t held = 0;
        {
            std::lock_guard lock(mutex_);
            const auto now = TokenBucket::Clock::now();
            if (bucket_.wait_time(now) > std::chrono::nanoseconds{0}) {  // in debt: hold this line back
                ++held_;
                return;
            }
            bucket_.take(1, now);
            held = held_;
            held_ = 0;
        }
        log(LogLevel::warning, held ? line + " (" + std::to_string(held) + " similar lines held back)" : line);
    }

private:
    std::mutex mutex_;
    TokenBucket bucket_{1, 5, TokenBucket::Clock::now()};
    std::uint64_t held_ = 0;
};

}  // namespace

Result<std::unique_ptr<Gateway>> Gateway::start(GatewayConfig config, DemoStarter demo, ApiInstaller api) {
    std::unique_ptr<Gateway> g(new Gateway());
    g->config_ = std::move(config);
    const auto& c = g->config_;

    NodeOptions opts;
    if (!c.node_id.empty()) opts.node_id = *NodeID::parse(c.node_id);
    opts.node_name = c.node_name;
    opts.threads = c.threads;
    opts.server.stream.limits.max_message_size = c.max_message_size;
    opts.server.stream.heartbeat_period = std::chrono::milliseconds(12000);  // a server's period (wire.md §6.3)
    // gateway.limits (docs/security.md "Connection limits"): both kinds of warning share one log budget.
    auto limit_log = std::make_shared<LimitLog>();
    if (c.limits.connections_per_address) {
        g->address_limiter_ = AddressLimiter::create(c.limits.connections_per_address);
        opts.address_limiter = g->address_limiter_;
        opts.on_limited = [limit_log](const std::string&, const std::string& reason) {
            limit_log->warn("connection refused: " + reason + " (gateway.limits.connections_per_address)");
        };
    }
    opts.read_rates = ReadRates{c.limits.messages_per_second, c.limits.bytes_per_second, c.limits.burst_s};
    if (opts.read_rates.enabled())
        opts.on_throttled = [limit_log](const std::string& peer) {
            limit_log->warn("connection from " + peer +
                            " over its rate (gateway.limits.messages_per_second / bytes_per_second): reads paused");
        };
    // A configured NodeID is what a new NodeID cache entry gets (a first start on a fresh machine).
    auto reservation = reserve_local_name(c.local, c.node_name, opts.node_id);
    if (!reservation) return reservation.take_error();
    if (*reservation && c.node_id.empty()) opts.node_id = (*reservation)->node_id;
    g->node_ = Node::create(opts);

    // rr+usb (docs/usb.md): a USB host on the node's executor when a device or discover: entry names
    // rr+usb, or usb.enabled is true; the devices reach it through the node's transports.
    if (usb_wanted(c)) {
#ifdef RR_HAVE_USB
        usb::UsbHostOptions uo;
        for (const auto& a : c.usb.allow) uo.allowed.push_back(usb::UsbDeviceId{a.vendor_id, a.product_id, a.interface_number});
        uo.hotplug = c.usb.hotplug;
        uo.poll_interval = c.usb.poll_interval;
        uo.log = [](std::string_view line) { log(LogLevel::debug, "rr+usb: " + std::string(line)); };
        auto host = usb::UsbHost::create(g->node_->io_context().get_executor(), uo);
        if (!host)
            return fail(host.error().type,
                        "rr+usb: " + host.error().message +
                            " (the configuration uses USB; in a container pass the bus in with --device /dev/bus/usb, "
                            "or turn USB off with usb.enabled: false)");
        g->usb_host_ = *host;
        usb::register_usb_transport(g->node_->transports(), g->usb_host_);
        log(LogLevel::info, std::string("rr+usb: USB host transport on (") +
                                (g->usb_host_->uses_hotplug() ? std::string("hotplug")
                                                              : "polling every " + std::to_string(c.usb.poll_interval.count()) + " ms") +
                                ")");
#else
        return fail(MessageErrorType::InvalidConfiguration,
                    "rr+usb: this rr-gateway was built without libusb-1.0, so the configuration's rr+usb devices cannot be "
                    "reached (rebuild with libusb-1.0-0-dev, or remove them)");
#endif
    }

    // gateway.auth: the gateway's own users and permissions (auth: gateway), before any device exists
    // (the demo node's login depends on it).
    auto auth = load_gateway_auth(c.auth);
    if (!auth) return auth.take_error();
    g->auth_ = *auth;

    std::vector<gateway::DeviceConfig> devices = c.devices;
    if (c.demo) {
        if (!demo) return fail(MessageErrorType::InvalidConfiguration, "demo devices are not built into this binary");
        NodeOptions dopts;
        dopts.node_name = c.node_name + ".demo";
        dopts.threads = 2;
        auto demo_reservation = reserve_local_name(c.local, dopts.node_name, NodeID{});
        if (!demo_reservation) return demo_reservation.take_error();
        if (*demo_reservation) dopts.node_id = (*demo_reservation)->node_id;
        // The demo node is a node like the gateway's: where the gateway listens on every address (the
        // default `::`), so does it, with the gateway's limits, and it announces itself when discovery
        // is on. While gateway.auth is on it stays on loopback and quiet: its services then require a
        // login only this process knows (docs/security.md "The demo node"), so announcing them would
        // only offer services nobody else can use.
        g->demo_public_ = !g->auth_ && listens_everywhere(c.listen);
        if (g->demo_public_) {
            // The gateway's own sessions to the demo devices (create, webcam) come from 127.0.0.1 too.
            if (c.limits.connections_per_address) {
                dopts.address_limiter = AddressLimiter::create(c.limits.connections_per_address + 2);
                dopts.on_limited = [limit_log](const std::string&, const std::string& reason) {
                    limit_log->warn("demo node: connection refused: " + reason + " (gateway.limits.connections_per_address)");
                };
            }
            dopts.read_rates = opts.read_rates;
        }
        g->demo_node_ = Node::create(dopts);
        auto demo_listener = open_tcp_listener(g->demo_node_, g->demo_public_ ? c.listen : std::string("127.0.0.1"), c.demo_port);
        if (!demo_listener) return demo_listener.take_error();
        *g->demo_bound_ = (*demo_listener)->local_endpoint();
        if (c.local) {
            if (auto r = serve_local(g->demo_node_, std::move(*demo_reservation)); !r) return r.take_error();
        }
        // With logins on, the demo node must not be a way around them: its port and rr+local socket are
        // open to every process on this computer, so its services require a login only this process
        // knows, and the gateway's own sessions to the demo devices use it.
        DemoLogin login;
        if (g->auth_) {
            auto password = random_demo_password();
            if (!password) return password.take_error();
            login = DemoLogin{std::string(kDemoUser), std::move(*password)};
        }
        auto demo_devices = demo(g->demo_node_, (*demo_listener)->port(), login);
        if (!demo_devices) return demo_devices.take_error();
        if (login.required()) {
            for (const auto& name : g->demo_node_->service_names()) {
                auto service = g->demo_node_->find_service(name);
                if (service && !service->requires_authentication())
                    return fail(MessageErrorType::InternalError,
                                "demo service \"" + name + "\" does not require a login while gateway.auth is on");
            }
        }
        for (auto& d : *demo_devices) {
            // A configured device of the same name wins over the demo one.
            bool taken = false;
            for (const auto& x : devices) taken |= x.name == d.name;
            if (!taken) devices.push_back(std::move(d));
        }
    }

    // Replayed devices (docs/recording.md "Replay"): each recording served by a service on the replay
    // node (loopback only; behind a login only this process knows while gateway.auth is on) and mirrored
    // like any device, so every kind of client sees it as a live one.
    if (!c.replays.empty()) {
        NodeOptions ropts;
        ropts.node_name = c.node_name + ".replay";
        ropts.threads = 1;
        g->replay_node_ = Node::create(ropts);
        auto replay_listener = open_tcp_listener(g->replay_node_, std::string("127.0.0.1"), 0);
        if (!replay_listener) return replay_listener.take_error();
        const auto replay_port = (*replay_listener)->port();
        DemoLogin login;
        if (g->auth_) {
            auto password = random_demo_password();
            if (!password) return password.take_error();
            login = DemoLogin{std::string(kDemoUser), std::move(*password)};
        }
        for (const auto& rc : c.replays) {
            record::ReplayOptions ro;
            ro.file = rc.file;
            ro.name = rc.name;
            ro.speed = rc.speed;
            ro.loop = rc.loop;
            ro.paused = rc.paused;
            ro.memory_bytes = c.recordings.replay_memory_bytes;
            ro.on_error = [](const std::string& device, const std::string& error) {
                log(LogLevel::error, "replay of " + device + " failed: " + error, LogContext{.device = device});
            };
            auto replay = record::ReplayDevice::open(ro);
            if (!replay) return fail(MessageErrorType::InvalidConfiguration, replay.error().message);
            const auto& name = (*replay)->name();
            for (const auto& x : devices)
                if (x.name == name)
                    return fail(MessageErrorType::InvalidConfiguration, "replay " + rc.file + ": device name \"" + name + "\" is taken");
            for (const auto& x : g->replays_)
                if (x->name() == name)
                    return fail(MessageErrorType::InvalidConfiguration, "replay " + rc.file + ": device name \"" + name + "\" is taken");
            if (login.required()) {
                PasswordTable users;
                users.add_user(login.username, login.password);
                (*replay)->service()->set_users(std::move(users));
            }
            if (auto r = g->replay_node_->register_service((*replay)->service()); !r) return r.take_error();
            gateway::DeviceConfig dc;
            dc.name = name;
            dc.url = "rr+tcp://127.0.0.1:" + std::to_string(replay_port) + "/?service=" + name;
            dc.username = login.username;
            dc.password = login.password;
            dc.backoff_initial = std::chrono::milliseconds(100);
            devices.push_back(std::move(dc));
            g->replays_.push_back(*replay);
        }
        for (const auto& r : g->replays_) r->start();
    }

    for (auto d : devices) {
        d.safety = c.safety.for_device(d.name);  // motion safety (docs/security.md "Motion safety")
        auto m = gateway::DeviceMirror::create(g->node_, d);
        if (!m) return m.take_error();
        // The gateway's roles apply to every device. A passthrough device checks its clients' passwords
        // itself; the roles then apply to the user name the device accepted (MirrorService::handle_entry).
        if (g->auth_) (*m)->mirror_service()->set_access(gateway::auth::MirrorAccess(g->auth_, d.name));
        g->devices_.push_back(*m);
    }

    if (c.tls.enabled()) {
        auto creds = load_tls(c.tls);
        if (!creds) return creds.take_error();
        g->tls_ = *creds;
    }

    http::HttpOptions hopts;
    hopts.allowed_origins = c.allowed_origins;
    if (hopts.allowed_origins.empty()) {
        // Default: the gateway's own pages on this machine.
        for (const char* host : {"localhost", "127.0.0.1", "[::1]"}) {
            hopts.allowed_origins.push_back(std::string("http://") + host + ":" + std::to_string(c.port));
            if (g->tls_) hopts.allowed_origins.push_back(std::string("https://") + host + ":" + std::to_string(c.port));
        }
    }
    hopts.static_root = c.web_root;
    hopts.websocket_deflate = c.websocket_compression.enabled;
    hopts.websocket_deflate_paths = c.websocket_compression.paths;
    hopts.websocket_gathered_writes = c.websocket_gathered_writes;
    for (const auto& p : c.trusted_proxies)
        if (auto n = http::parse_ip_network(p)) hopts.trusted_proxies.push_back(*n);
    hopts.on_websocket = [](const std::string& line) { log(LogLevel::info, line); };
    if (log_enabled(LogLevel::debug)) {
        // The access log: one debug line per HTTP response, with the client and its request.
        hopts.on_response = [](std::string_view client, std::string_view request, unsigned status) {
            log(LogLevel::debug, "HTTP " + std::to_string(status), LogContext{.client = client, .request = request});
        };
    }
    g->http_ = std::make_shared<http::HttpServer>(g->node_, hopts);
    Gateway* self = g.get();
    g->http_->add_route(bhttp::verb::get, "/livez", [](const http::Request& req, http::Responder respond) {
        respond(http::make_response(req, bhttp::status::ok, "ok\n"));
    });
    g->http_->add_route(bhttp::verb::get, "/readyz", [self](const http::Request& req, http::Responder respond) {
        std::string body;
        for (const auto& d : self->devices_) {
            auto s = d->status();
            if (s.required && s.state != gateway::DeviceState::connected)
                body += s.name + ": " + std::string(gateway::device_state_name(s.state)) +
                        (s.reason.empty() ? "" : " (" + s.reason + ")") + "\n";
        }
        const bool ready = body.empty();
        respond(http::make_response(req, ready ? bhttp::status::ok : bhttp::status::service_unavailable,
                                    ready ? "ready\n" : "not ready:\n" + body));
    });
    g->http_->add_route(bhttp::verb::get, "/metrics", [self](const http::Request& req, http::Responder respond) {
        respond(http::make_response(req, bhttp::status::ok, self->metrics_text(), "text/plain; version=0.0.4; charset=utf-8"));
    });
    std::shared_ptr<gateway::JsonApi> json_api;
    if (api) json_api = api(*g->http_, g->devices_, g->auth_);
    // Recording (docs/recording.md): from the JSON API and the configuration's `record:` entries.
    if (json_api) {
        g->recordings_ = std::make_shared<record::Recordings>(json_api, c.recordings, [](const record::RecordingStatus& s, std::string_view what) {
            const bool failed = what == "failed", refused = what == "refused";
            log(failed ? LogLevel::error : refused ? LogLevel::warning : LogLevel::info,
                (refused ? "recording of " + s.spec.device + " refused" : "recording " + std::to_string(s.id) + " of " + s.spec.device + ": " + std::string(what)) +
                    (failed || refused ? " (" + s.error + ")" : s.files.empty() ? "" : " (" + s.files.back() + ")"),
                LogContext{.device = s.spec.device});
        });
        log(LogLevel::debug, "recordings go below " + g->recordings_->root()->path());
        record::install_recording_routes(*g->http_, json_api, g->recordings_);
        record::install_replay_routes(*g->http_, json_api, g->replays_);
        // The Foxglove WebSocket protocol at /foxglove (docs/foxglove.md).
        foxglove::FoxgloveOptions fo;
        fo.objects = c.foxglove_objects;
        fo.clock = c.foxglove_clock;
        g->foxglove_ = foxglove::install_foxglove(*g->http_, json_api, std::move(fo));
    }

    // Node discovery (docs/discovery.md): announce the gateway, keep a table of nodes, and turn the
    // services that `discover:` filters select into devices.
    if (c.discovery.enabled) {
        auto dopts = discovery_options(c.discovery, g->node_, g->tcp_bound_);
        dopts.listen = true;
        // Services are read over the node's transports (rr+tcp, rr+local, and rr+usb when on).
        dopts.transports = &g->node_->transports();
        // The demo node is part of the gateway, not a node it found (its devices are already served).
        if (g->demo_node_) dopts.ignored_nodes.push_back(g->demo_node_->node_id());
        g->discovery_ = discovery::NodeDiscovery::create(g->node_->io_context().get_executor(), dopts);
        std::weak_ptr<discovery::NodeDiscovery> weak_discovery = g->discovery_;
        g->node_->on_services_changed([weak_discovery] {
            if (auto d = weak_discovery.lock()) d->services_changed();
        });
        g->discovered_ = DiscoveredDevices::create(g->node_, g->discovery_, c.discover,
                                                   [self](const std::string& name) { return self->device(name) != nullptr; });
        g->discovered_->set_api(json_api);
        g->discovered_->set_auth(g->auth_);
        g->discovered_->set_safety(c.safety);
        if (json_api) {
            std::weak_ptr<DiscoveredDevices> weak = g->discovered_;
            gateway::JsonApi::DiscoveryHooks hooks;
            hooks.list = [weak, self] {
                auto d = weak.lock();
                auto j = d ? d->list() : nlohmann::json{{"nodes", nlohmann::json::array()}};
                j["usb_problems"] = self->usb_problems();
                return j;
            };
            hooks.add = [weak](const nlohmann::json& body, gateway::JsonApi::Done done) {
                auto d = weak.lock();
                if (!d) return done(gateway::ApiResult::failed(gateway::api_error(503, MessageErrorType::InvalidState, "gateway stopping")));
                if (!body.is_object() || !body.contains("nodeid") || !body["nodeid"].is_string() || !body.contains("service") ||
                    !body["service"].is_string() || (body.contains("name") && !body["name"].is_string()))
                    return done(gateway::ApiResult::failed(gateway::api_error(
                        400, MessageErrorType::InvalidArgument, "the body must be {\"nodeid\": …, \"service\": …, \"name\"?: …}")));
                auto id = NodeID::parse(body["nodeid"].get<std::string>());
                if (!id) return done(gateway::ApiResult::failed(gateway::api_error(400, MessageErrorType::InvalidArgument, "not a NodeID")));
                auto r = d->add(*id, body["service"].get<std::string>(), body.value("name", std::string()));
                if (!r) {
                    const auto t = r.error().type;
                    const unsigned status = (t == MessageErrorType::NodeNotFound || t == MessageErrorType::ServiceNotFound) ? 404 : 400;
                    return done(gateway::ApiResult::failed(gateway::api_error(status, t, r.error().message)));
                }
                done(gateway::ApiResult::ok(gateway::JsonApi::status_json((*r)->status())));
            };
            json_api->set_discovery_hooks(std::move(hooks));
        }
        g->discovered_->start();
        // The demo node announces itself too (and answers requests), as a node of its own would.
        if (g->demo_node_ && g->demo_public_ && c.discovery.announce) {
            auto demo_opts = discovery_options(c.discovery, g->demo_node_, g->demo_bound_);
            demo_opts.listen = false;  // no table of its own: the gateway keeps one
            g->demo_discovery_ = discovery::NodeDiscovery::create(g->demo_node_->io_context().get_executor(), demo_opts);
            std::weak_ptr<discovery::NodeDiscovery> weak_demo = g->demo_discovery_;
            g->demo_node_->on_services_changed([weak_demo] {
                if (auto d = weak_demo.lock()) d->services_changed();
            });
        }
    }
    for (auto& d : g->devices_) {
        d->set_state_listener([](const gateway::DeviceStatus& s) {
            log(s.state == gateway::DeviceState::connected ? LogLevel::info : LogLevel::warning,
                "device " + s.name + ": " + std::string(gateway::device_state_name(s.state)) +
                    (s.reason.empty() ? "" : " (" + s.reason + ")"), LogContext{.device = s.name});
        });
        // What the motion guard did (a clamp, a refusal, a stop of its own): docs/security.md "Motion safety".
        if (const auto& guard = d->motion())
            guard->set_event_listener([name = d->config().name](const std::string& what) {
                log(LogLevel::info, "motion safety: " + what, LogContext{.device = name});
            });
        d->start();
    }
    if (g->recordings_)
        for (const auto& spec : c.record) g->recordings_->start_when_connected(spec);

    // The gateway's one TCP port: raw RR, HTTP and WebSocket upgrades (server/http), and with
    // gateway.tls also TLS, rrs+tcp, HTTPS and WSS (server/transport/tls).
    TcpListenerOptions tcp_opts;
    tcp_opts.http = http::http_handler(g->http_);
    if (g->tls_) {
        auto tls = std::make_shared<TlsListenOptions>();
        tls->credentials = g->tls_;
        tls->node_id = g->node_->node_id();
        tls->node_name = g->node_->node_name();
        tls->timeout = g->node_->options().first_bytes_timeout;
        tls->required = c.tls.required;
        tls->https = http::https_handler(g->http_);
        tls->on_failure = [failures = g->tls_failures_](const std::string& peer, const std::string& reason) {
            failures->fetch_add(1);
            log(LogLevel::debug, "TLS from " + peer + ": " + reason);
        };
        tcp_opts.tls = std::move(tls);
    }
    auto listener = open_tcp_listener(g->node_, c.listen, c.port, std::move(tcp_opts));
    if (!listener) return listener.take_error();
    if (!(*listener)->fallback_note().empty()) log(LogLevel::warning, "gateway port: " + (*listener)->fallback_note());
    g->port_ = (*listener)->port();
    *g->tcp_bound_ = (*listener)->local_endpoint();
    if (c.local) {
        if (auto r = serve_local(g->node_, std::move(*reservation)); !r) return r.take_error();
    }
    if (g->demo_discovery_) {
        if (auto r = g->demo_discovery_->start(); !r) return r.take_error();
    }
    if (g->discovery_) {
        if (auto r = g->discovery_->start(); !r) return r.take_error();
        if (c.discovery.announce && g->tcp_bound_->address().is_unspecified())
            log(LogLevel::info, "node discovery: announcing " + c.node_name + (g->demo_discovery_ ? " and " + c.node_name + ".demo" : "") +
                                    " on the local network, as an official node does (off: --no-discovery, discovery.enabled: false)");
        // Other sources of the table: this computer's rr+local nodes and the USB devices.
        if (c.discovery.local) {
            discovery::LocalSourceOptions lo;
            lo.dirs = local::default_node_directories();
            g->local_source_ = discovery::LocalDiscoverySource::start(g->node_->io_context().get_executor(), g->discovery_, lo);
        }
#ifdef RR_HAVE_USB
        if (g->usb_host_)
            g->usb_source_ = usb::UsbDiscoverySource::start(g->node_->io_context().get_executor(), g->usb_host_, g->discovery_);
#endif
    }
    return g;
}

Result<std::shared_ptr<TlsServerCredentials>> load_tls(const GatewayTlsConfig& t) {
    auto creds = TlsServerCredentials::load(
        TlsServerFiles{t.certificate, t.private_key, t.client_ca, t.node_certificate, t.node_private_key});
    if (!creds) return fail(MessageErrorType::InvalidConfiguration, "gateway.tls: " + creds.error().message);
    return *creds;
}

Result<void> Gateway::reload_tls() {
    if (!tls_) return fail(MessageErrorType::InvalidState, "no TLS configured (gateway.tls)");
    if (auto r = tls_->reload(); !r) return fail(MessageErrorType::InvalidConfiguration, "gateway.tls: " + r.error().message);
    return {};
}

Gateway::~Gateway() { stop(); }

std::vector<std::shared_ptr<gateway::DeviceMirror>> Gateway::discovered_devices() const {
    return discovered_ ? discovered_->devices() : std::vector<std::shared_ptr<gateway::DeviceMirror>>{};
}

nlohmann::json Gateway::usb_problems() const {
    auto out = nlohmann::json::array();
#ifdef RR_HAVE_USB
    if (!usb_host_) return out;
    for (const auto& d : usb_host_->devices()) {
        if (!d.error) continue;
        char id[16];
        std::snprintf(id, sizeof id, "%04x:%04x", d.vendor_id, d.product_id);
        out.push_back({{"device", id}, {"path", d.device_path}, {"error", d.error->message}});
    }
#endif
    return out;
}

void Gateway::stop() {
    // JSON clients first, while everything still runs: every JSON WebSocket (the JSON API's, Foxglove's)
    // gets 1001 Going Away (a restart, not a network failure). RR connections get theirs, over WebSocket
    // as 1001 too, when the node shuts down below.
    if (http_) http_->go_away();
    if (discovered_) discovered_->stop();
    if (local_source_) local_source_->stop();
#ifdef RR_HAVE_USB
    if (usb_source_) usb_source_->stop();
#endif
    if (demo_discovery_) demo_discovery_->stop();
    // Before the node's threads stop. An interrogation still connecting after this is freed when the io
    // threads go (ConnectionLogic::on_abandoned); 6 s here made a loaded gateway miss a 10 s SIGTERM grace.
    if (discovery_) discovery_->stop(std::chrono::milliseconds(2000));
    // Recordings close their files (summary and index) while the devices still run.
    if (recordings_) recordings_->stop_all();
    for (auto& d : devices_) d->stop();
    for (auto& r : replays_) r->stop();
    if (replay_node_) replay_node_->shutdown();
#ifdef RR_HAVE_USB
    if (usb_host_) {
        // Before the node's threads stop: the host's strand runs on them.
        usb_host_->shutdown();
        for (int i = 0; i < 200 && !usb_host_->idle(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
#endif
    if (node_) node_->shutdown();
    if (demo_node_) demo_node_->shutdown();
}

std::shared_ptr<gateway::DeviceMirror> Gateway::device(std::string_view name) const {
    for (const auto& d : devices_)
        if (d->config().name == name) return d;
    return nullptr;
}

bool Gateway::ready() const {
    for (const auto& d : devices_) {
        auto s = d->status();
        if (s.required && s.state != gateway::DeviceState::connected) return false;
    }
    return true;
}

std::string Gateway::metrics_text() const {
    std::ostringstream o;
    auto stats = node_->stats();
    auto all = devices_;  // configured devices, then discovered ones
    for (auto& d : discovered_devices()) all.push_back(d);
    o << "# HELP rr_gateway_connections Open RR connections (TCP and WebSocket) to the gateway.\n"
         "# TYPE rr_gateway_connections gauge\n"
      << "rr_gateway_connections " << node_->connection_count() << "\n"
      << "# HELP rr_gateway_accepted_connections_total RR connections accepted since start.\n"
         "# TYPE rr_gateway_accepted_connections_total counter\n"
      << "rr_gateway_accepted_connections_total " << stats->connections_total.load() << "\n"
      << "# HELP rr_gateway_limited_total Times a gateway.limits limit bit: connections refused, reads paused.\n"
         "# TYPE rr_gateway_limited_total counter\n"
      << "rr_gateway_limited_total{limit=\"connections_per_address\"} "
      << (address_limiter_ ? address_limiter_->refused() : 0) << "\n"
      << "rr_gateway_limited_total{limit=\"rate\"} " << node_->reads_throttled() << "\n"
      << "# HELP rr_gateway_messages_total RR messages to and from clients.\n"
         "# TYPE rr_gateway_messages_total counter\n"
      << "rr_gateway_messages_total{direction=\"in\"} " << stats->messages_in.load() << "\n"
      << "rr_gateway_messages_total{direction=\"out\"} " << stats->messages_out.load() << "\n"
      << "# HELP rr_gateway_bytes_total Bytes to and from clients.\n"
         "# TYPE rr_gateway_bytes_total counter\n"
      << "rr_gateway_bytes_total{direction=\"in\"} " << stats->bytes_in.load() << "\n"
      << "rr_gateway_bytes_total{direction=\"out\"} " << stats->bytes_out.load() << "\n"
      << "# HELP rr_gateway_tls_failures_total TLS connections that failed before serving (handshake, certificate, timeout).\n"
         "# TYPE rr_gateway_tls_failures_total counter\n"
      << "rr_gateway_tls_failures_total " << tls_failures_->load() << "\n";
    if (auth_) {
        const auto& a = auth_->counters();
        o << "# HELP rr_gateway_login_failures_total Failed logins to the gateway (wrong password, unknown user or token, bad JWT), by channel.\n"
             "# TYPE rr_gateway_login_failures_total counter\n"
          << "rr_gateway_login_failures_total{channel=\"rr\"} " << a.failed_rr.load() << "\n"
          << "rr_gateway_login_failures_total{channel=\"http\"} " << a.failed_http.load() << "\n"
          << "rr_gateway_login_failures_total{channel=\"token\"} " << a.failed_token.load() << "\n"
          << "rr_gateway_login_failures_total{channel=\"websocket\"} " << a.failed_websocket.load() << "\n"
          << "# HELP rr_gateway_login_rate_limited_total Login attempts refused because their address was locked out after failures.\n"
             "# TYPE rr_gateway_login_rate_limited_total counter\n"
          << "rr_gateway_login_rate_limited_total " << a.rate_limited.load() << "\n"
          << "# HELP rr_gateway_login_lockouts_total Client addresses locked out after too many failed logins.\n"
             "# TYPE rr_gateway_login_lockouts_total counter\n"
          << "rr_gateway_login_lockouts_total " << a.lockouts.load() << "\n"
          << "# HELP rr_gateway_logins_total Successful logins to the gateway.\n"
             "# TYPE rr_gateway_logins_total counter\n"
          << "rr_gateway_logins_total " << a.succeeded.load() << "\n"
          << "# HELP rr_gateway_permission_denied_total Member requests refused by the gateway's permissions.\n"
             "# TYPE rr_gateway_permission_denied_total counter\n"
          << "rr_gateway_permission_denied_total " << a.denied.load() << "\n";
    }

    o << "# HELP rr_gateway_device_up Device state: 1 when connected.\n# TYPE rr_gateway_device_up gauge\n";
    for (const auto& d : all) {
        auto s = d->status();
        o << "rr_gateway_device_up{device=\"" << escape_label(s.name) << "\",state=\""
          << gateway::device_state_name(s.state) << "\"} " << (s.state == gateway::DeviceState::connected ? 1 : 0)
          << "\n";
    }
    // One status per device for both gauges (status() takes the device's locks once).
    std::vector<gateway::DeviceStatus> statuses;
    statuses.reserve(all.size());
    for (const auto& d : all) statuses.push_back(d->status());
    o << "# HELP rr_gateway_device_clients RR client sessions of the device's service on the gateway.\n"
         "# TYPE rr_gateway_device_clients gauge\n";
    for (const auto& s : statuses)
        o << "rr_gateway_device_clients{device=\"" << escape_label(s.name) << "\"} " << s.downstream_sessions << "\n";
    o << "# HELP rr_gateway_device_passthrough_sessions Upstream sessions of clients' own to an auth: passthrough device "
         "(native clients and JSON API device logins; 0 for shared devices).\n"
         "# TYPE rr_gateway_device_passthrough_sessions gauge\n";
    for (const auto& s : statuses)
        o << "rr_gateway_device_passthrough_sessions{device=\"" << escape_label(s.name) << "\"} " << s.upstream_sessions << "\n";
    auto counter = [&](const char* name, const char* help, auto field) {
        o << "# HELP " << name << " " << help << "\n# TYPE " << name << " counter\n";
        for (const auto& d : all)
            o << name << "{device=\"" << escape_label(d->config().name) << "\"} " << field(d->counters()) << "\n";
    };
    counter("rr_gateway_device_requests_total", "Requests forwarded to the device.",
            [](const gateway::DeviceCounters& c) { return c.requests.load(); });
    counter("rr_gateway_device_request_errors_total", "Requests answered with an error.",
            [](const gateway::DeviceCounters& c) { return c.request_errors.load(); });
    counter("rr_gateway_device_events_total", "Events received from the device.",
            [](const gateway::DeviceCounters& c) { return c.events.load(); });
    counter("rr_gateway_device_wire_packets_total", "Wire values received from the device.",
            [](const gateway::DeviceCounters& c) { return c.wire_packets_in.load(); });
    counter("rr_gateway_device_pipe_packets_total", "Pipe packets forwarded.",
            [](const gateway::DeviceCounters& c) { return c.pipe_packets.load(); });
    counter("rr_gateway_device_drops_total", "Pipe packets and events a client could not take (queue full).",
            [](const gateway::DeviceCounters& c) { return c.pipe_drops.load() + c.event_drops.load(); });
    counter("rr_gateway_device_reconnects_total", "Times the device connection was lost.",
            [](const gateway::DeviceCounters& c) { return c.reconnects.load(); });

    o << "# HELP rr_gateway_request_duration_seconds Device request round trip through the gateway.\n"
         "# TYPE rr_gateway_request_duration_seconds histogram\n";
    for (const auto& d : all) {
        const auto& c = d->counters();
        const std::string label = "device=\"" + escape_label(d->config().name) + "\"";
        std::uint64_t cumulative = 0;
        for (std::size_t i = 0; i < std::size(gateway::kLatencyBuckets); ++i) {
            cumulative += c.latency_buckets[i].load();
            o << "rr_gateway_request_duration_seconds_bucket{" << label << ",le=\"" << gateway::kLatencyBuckets[i]
              << "\"} " << cumulative << "\n";
        }
        cumulative += c.latency_buckets[std::size(gateway::kLatencyBuckets)].load();
        o << "rr_gateway_request_duration_seconds_bucket{" << label << ",le=\"+Inf\"} " << cumulative << "\n";
        o << "rr_gateway_request_duration_seconds_sum{" << label << "} " << (c.latency_sum_us.load() / 1e6) << "\n";
        o << "rr_gateway_request_duration_seconds_count{" << label << "} " << cumulative << "\n";
    }
    if (discovery_) {
        const auto dc = discovery_->counters();
        o << "# HELP rr_gateway_discovery_nodes Nodes in the discovery table.\n# TYPE rr_gateway_discovery_nodes gauge\n"
          << "rr_gateway_discovery_nodes " << discovery_->size() << "\n"
          << "# HELP rr_gateway_discovery_announces_total Node announcements accepted.\n"
             "# TYPE rr_gateway_discovery_announces_total counter\n"
          << "rr_gateway_discovery_announces_total " << dc.announces << "\n"
          << "# HELP rr_gateway_discovery_evictions_total Nodes evicted from the full discovery table (oldest first).\n"
             "# TYPE rr_gateway_discovery_evictions_total counter\n"
          << "rr_gateway_discovery_evictions_total " << dc.evictions << "\n"
          << "# HELP rr_gateway_discovery_url_evictions_total URLs evicted by the per-node cap.\n"
             "# TYPE rr_gateway_discovery_url_evictions_total counter\n"
          << "rr_gateway_discovery_url_evictions_total " << dc.url_evictions << "\n"
          << "# HELP rr_gateway_discovery_expired_total Nodes lost after 60 s without an announce.\n"
             "# TYPE rr_gateway_discovery_expired_total counter\n"
          << "rr_gateway_discovery_expired_total " << dc.expired << "\n"
          << "# HELP rr_gateway_discovery_packets_rejected_total Discovery datagrams rejected, by reason (own packets not counted).\n"
             "# TYPE rr_gateway_discovery_packets_rejected_total counter\n";
        for (int r = 0; r <= static_cast<int>(rr::discovery::Reject::own_packet); ++r) {
            const auto reason = static_cast<rr::discovery::Reject>(r);
            if (reason == rr::discovery::Reject::own_packet) continue;
            o << "rr_gateway_discovery_packets_rejected_total{reason=\"" << rr::discovery::reject_name(reason) << "\"} "
              << dc.rejected[r] << "\n";
        }
        o << "# HELP rr_gateway_discovered_devices Devices added by discovery.\n# TYPE rr_gateway_discovered_devices gauge\n"
          << "rr_gateway_discovered_devices " << discovered_devices().size() << "\n";
    }
    return o.str();
}

}  // namespace rr::server::app
