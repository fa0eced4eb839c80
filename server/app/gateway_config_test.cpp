#include <array>
#include <catch2/catch.hpp>

#include "server/app/gateway_auth_config.hpp"
#include "server/app/gateway_config.hpp"

using namespace rr;
using namespace rr::server::app;

namespace {

// `yaml` (as bad.yaml) is refused with InvalidConfiguration, and the message starts with `expect`.
void check_refused(const std::string& yaml, const std::string& expect) {
    auto c = parse_gateway_config(yaml, "bad.yaml");
    INFO(yaml);
    REQUIRE_FALSE(c);
    CHECK(c.error().type == MessageErrorType::InvalidConfiguration);
    CHECK_THAT(c.error().message, Catch::StartsWith(expect));
}

}  // namespace

TEST_CASE("a full configuration parses") {
    auto c = parse_gateway_config(R"(
gateway:
  listen: 127.0.0.1
  port: 9090
  node_name: lab.gateway
  allowed_origins: [http://localhost:9090]
  log_level: debug
demo:
  enabled: false
devices:
  - name: reynard
    url: rr+tcp://localhost:29200/?service=reynard
  - name: arm
    url: rr+tcp://10.0.0.5:48653/?service=robot
    username: op
    password: secret
    required: false
)", "test.yaml");
    REQUIRE(c);
    CHECK(c->listen == "127.0.0.1");
    CHECK(c->port == 9090);
    CHECK(c->node_name == "lab.gateway");
    CHECK_FALSE(c->demo);
    REQUIRE(c->devices.size() == 2);
    CHECK(c->devices[1].username == "op");
    CHECK_FALSE(c->devices[1].required);
    CHECK(c->allowed_origins == std::vector<std::string>{"http://localhost:9090"});
}

TEST_CASE("an empty configuration gives the defaults (demo on, port 8080)") {
    auto c = parse_gateway_config("", "empty.yaml");
    REQUIRE(c);
    CHECK(c->port == 8080);
    CHECK(c->demo);
    CHECK(c->devices.empty());
    CHECK(c->local);  // rr+local served under the gateway's NodeName unless turned off
}

// Issue 40: with no options the gateway behaves as an official server node (ServerNodeSetup): both IP
// families on one socket, announced, answering discovery requests.
TEST_CASE("an empty configuration is an official server node: both IP families, discovery on") {
    auto c = parse_gateway_config("", "empty.yaml");
    REQUIRE(c);
    CHECK(c->listen == "::");
    CHECK(c->discovery.enabled);
    CHECK(c->discovery.announce);
    CHECK_FALSE(c->discovery.ipv4_broadcast);  // opt-in, as the official IPV4_BROADCAST flag
    // The safe parts of the defaults stay: Origin checks (same origin only), connection limits.
    CHECK(c->allowed_origins.empty());
    CHECK(c->limits.connections_per_address == 256);
    CHECK(c->max_message_size == 12u * 1024u * 1024u);
}

TEST_CASE("discovery.enabled: false and --no-discovery turn discovery off, and discover: entries need it") {
    auto off = parse_gateway_config("discovery:\n  enabled: false\n", "t.yaml");
    REQUIRE(off);
    CHECK_FALSE(off->discovery.enabled);
    const char* argv[] = {"rr-gateway", "--no-discovery"};
    auto cmd = parse_command_line(2, argv);
    REQUIRE(cmd);
    GatewayConfig c;
    REQUIRE(apply_overrides(c, *cmd));
    CHECK_FALSE(c.discovery.enabled);
    // --discovery (the default) overrides a file that turned it off.
    const char* on_argv[] = {"rr-gateway", "--discovery"};
    auto on = parse_command_line(2, on_argv);
    REQUIRE(on);
    REQUIRE(apply_overrides(*off, *on));
    CHECK(off->discovery.enabled);
    CHECK_FALSE(parse_command_line(2, std::array<const char*, 2>{"g", "--no-discovery=1"}.data()));
    // A discover: entry cannot work without discovery: refused, naming both.
    auto both = parse_gateway_config("discovery: {enabled: false}\ndiscover:\n  - type: a.B\n", "t.yaml");
    REQUIRE_FALSE(both);
    CHECK_THAT(both.error().message, Catch::Contains("t.yaml:1: discover: needs discovery"));
    auto rules = parse_gateway_config("discover:\n  - type: a.B\n", "t.yaml");
    REQUIRE(rules);
    auto r = apply_overrides(*rules, *cmd);
    REQUIRE_FALSE(r);
    CHECK_THAT(r.error().message, Catch::Contains("--no-discovery"));
}

TEST_CASE("gateway.local: false and --no-local turn the gateway's rr+local off") {
    auto off = parse_gateway_config("gateway:\n  local: false\n", "t.yaml");
    REQUIRE(off);
    CHECK_FALSE(off->local);
    auto bad = parse_gateway_config("gateway:\n  local: sometimes\n", "bad.yaml");
    REQUIRE_FALSE(bad);
    CHECK_THAT(bad.error().message, Catch::Contains("bad.yaml:2: gateway.local: expected true or false"));
    const char* argv[] = {"rr-gateway", "--no-local"};
    auto cmd = parse_command_line(2, argv);
    REQUIRE(cmd);
    GatewayConfig c;
    REQUIRE(c.local);
    REQUIRE(apply_overrides(c, *cmd));
    CHECK_FALSE(c.local);
}

TEST_CASE("foxglove.objects: objects below a device's root for the Foxglove WebSocket") {
    auto c = parse_gateway_config("foxglove:\n  objects:\n    webcam: [\"Webcams[0]\", \"Webcams[1]\"]\n", "t.yaml");
    REQUIRE(c);
    REQUIRE(c->foxglove_objects.count("webcam") == 1);
    CHECK(c->foxglove_objects.at("webcam") == std::vector<std::string>{"Webcams[0]", "Webcams[1]"});
    check_refused("foxglove:\n  objects: [1]\n", "bad.yaml:2: foxglove.objects: expected a map");
    check_refused("foxglove:\n  object: {}\n", "bad.yaml:2: foxglove.object: unknown key");
    auto clock = parse_gateway_config("foxglove:\n  clock: sim\n", "t.yaml");
    REQUIRE(clock);
    CHECK(clock->foxglove_clock == "sim");
}

TEST_CASE("configuration errors name the key and the line") {
    struct Case {
        const char* yaml;
        const char* expect;
    };
    for (auto [yaml, expect] : {
             Case{"gateway:\n  port: 8080\n  prot: 1\n", "bad.yaml:3: gateway.prot: unknown key"},
             Case{"gateway:\n  port: 70000\n", "bad.yaml:2: gateway.port: must be at most 65535"},
             Case{"gateway:\n  port: eighty\n", "bad.yaml:2: gateway.port: expected a non-negative integer"},
             Case{"devices:\n  - name: a\n    url: http://x/\n", "bad.yaml:3: devices.a.url: invalid connection URL"},
             Case{"devices:\n  - name: a\n    url: rr+tcp://x:1/\n", "bad.yaml:3: devices.a.url: names no service"},
             Case{"devices:\n  - name: a\n", "bad.yaml:2: devices[].url: missing"},
             Case{"devices:\n  - name: a\n    url: rr+tcp://x/?service=s\n  - name: a\n    url: rr+tcp://y/?service=s\n",
                  "bad.yaml:4: devices.a: duplicate device name"},
             Case{"demo:\n  enabled: maybe\n", "bad.yaml:2: demo.enabled: expected true or false"},
             Case{"gateway: [1, 2]\n", "bad.yaml:1: gateway: expected a mapping"},
             Case{"gateway:\n  port: [\n", "bad.yaml:"},
             Case{"gateway:\n  log_level: loud\n", "bad.yaml:2: gateway.log_level: unknown level"},
             Case{"gateway:\n  log_format: xml\n", "bad.yaml:2: gateway.log_format: unknown format \"xml\""},
             Case{"gateway:\n  node_id: not-a-uuid\n", "bad.yaml:2: gateway.node_id: not a NodeID"},
         }) {
        check_refused(yaml, expect);
    }
}

TEST_CASE("usb: starts when the configuration names rr+usb, or when enabled, allow-list ids") {
    auto none = parse_gateway_config("devices:\n  - name: a\n    url: rr+tcp://x:1/?service=s\n", "t.yaml");
    REQUIRE(none);
    CHECK(none->usb.enabled == UsbSettings::Mode::automatic);
    CHECK_FALSE(usb_wanted(*none));
    auto dev = parse_gateway_config("devices:\n  - name: b\n    url: rr+usb:///?nodename=board&service=s\n", "t.yaml");
    REQUIRE(dev);
    CHECK(usb_wanted(*dev));
    auto disc = parse_gateway_config("discover:\n  - type: a.B\n    transports: [rr+local, rr+usb]\n", "t.yaml");
    REQUIRE(disc);
    CHECK(usb_wanted(*disc));
    CHECK(disc->discovery.enabled);
    CHECK(disc->discovery.local);
    auto any = parse_gateway_config("discover:\n  - type: a.B\n", "t.yaml");  // no transports: USB not started
    REQUIRE(any);
    CHECK_FALSE(usb_wanted(*any));
    auto on = parse_gateway_config(R"(
usb:
  enabled: true
  hotplug: false
  poll_interval_ms: 500
  allow:
    - {vid: 0x1209, pid: 0x0001}
    - {vid: 4617, pid: 0xBEEF, interface: 2}
discovery:
  local: false
)", "t.yaml");
    REQUIRE(on);
    CHECK(usb_wanted(*on));
    CHECK_FALSE(on->usb.hotplug);
    CHECK(on->usb.poll_interval == std::chrono::milliseconds(500));
    REQUIRE(on->usb.allow.size() == 2);
    CHECK(on->usb.allow[0].vendor_id == 0x1209);
    CHECK(on->usb.allow[0].product_id == 0x0001);
    CHECK(on->usb.allow[0].interface_number == 0);
    CHECK(on->usb.allow[1].vendor_id == 0x1209);
    CHECK(on->usb.allow[1].product_id == 0xBEEF);
    CHECK(on->usb.allow[1].interface_number == 2);
    CHECK_FALSE(on->discovery.local);
    auto autom = parse_gateway_config("usb:\n  enabled: auto\n", "t.yaml");
    REQUIRE(autom);
    CHECK_FALSE(usb_wanted(*autom));

    struct Case {
        const char* yaml;
        const char* expect;
    };
    for (auto [yaml, expect] : {
             Case{"usb:\n  enabled: maybe\n", "bad.yaml:2: usb.enabled: expected true, false or auto"},
             Case{"usb:\n  allow:\n    - {vid: 0x1209}\n", "bad.yaml:3: usb.allow[0].pid: missing"},
             Case{"usb:\n  allow:\n    - {vid: 0x12345, pid: 1}\n", "bad.yaml:3: usb.allow[0].vid: must be at most 65535"},
             Case{"usb:\n  allow:\n    - {vid: 12ab, pid: 1}\n", "bad.yaml:3: usb.allow[0].vid: expected a number"},
             Case{"usb:\n  allow:\n    - {vid: 1, pid: 1, interface: 256}\n", "bad.yaml:3: usb.allow[0].interface: must be at most 255"},
             Case{"usb:\n  allow:\n    - {vid: 1, pid: 1, if: 0}\n", "bad.yaml:3: usb.allow[0].if: unknown key"},
             Case{"usb:\n  poll_interval_ms: 5\n", "bad.yaml:2: usb.poll_interval_ms: must be at least 100"},
             Case{"usb:\n  enabled: false\ndevices:\n  - name: b\n    url: rr+usb:///?nodename=x&service=s\n",
                  "bad.yaml:2: devices.b.url: rr+usb is turned off"},
             Case{"discovery:\n  local: yes please\n", "bad.yaml:2: discovery.local: expected true or false"},
         }) {
        check_refused(yaml, expect);
    }
    // A --device flag naming rr+usb with USB turned off is refused too.
    auto off = parse_gateway_config("usb:\n  enabled: false\n", "t.yaml");
    REQUIRE(off);
    const char* argv[] = {"rr-gateway", "--device", "b=rr+usb:///?nodename=x&service=s"};
    auto cmd = parse_command_line(3, argv);
    REQUIRE(cmd);
    auto r = apply_overrides(*off, *cmd);
    REQUIRE_FALSE(r);
    CHECK_THAT(r.error().message, Catch::Contains("rr+usb is turned off"));
}

TEST_CASE("command-line flags override the file, including the official RR flags") {
    const char* argv[] = {"rr-gateway", "--config", "x.yaml", "--port=9000", "--robotraconteur-nodename=gw2",
                          "--device", "reynard=rr+tcp://localhost:29200/?service=reynard", "--no-demo",
                          "--robotraconteur-log-level", "WARNING"};
    auto cmd = parse_command_line(10, argv);
    REQUIRE(cmd);
    CHECK(cmd->config_file == "x.yaml");
    GatewayConfig c;
    REQUIRE(apply_overrides(c, *cmd));
    CHECK(c.port == 9000);
    CHECK(c.node_name == "gw2");
    CHECK_FALSE(c.demo);
    CHECK(c.log_level == "warning");
    REQUIRE(c.devices.size() == 1);
    CHECK(c.devices[0].name == "reynard");
}

TEST_CASE("log_format: the key and --log-format (flag wins)") {
    auto c = parse_gateway_config("gateway:\n  log_format: json\n", "x.yaml");
    REQUIRE(c);
    CHECK(c->log_format == "json");
    CHECK(GatewayConfig{}.log_format == "text");
    const char* argv[] = {"rr-gateway", "--log-format", "text"};
    auto cmd = parse_command_line(3, argv);
    REQUIRE(cmd);
    REQUIRE(apply_overrides(*c, *cmd));
    CHECK(c->log_format == "text");
    const char* bad[] = {"rr-gateway", "--log-format=yaml"};
    auto cmd2 = parse_command_line(2, bad);
    REQUIRE(cmd2);
    auto r = apply_overrides(*c, *cmd2);
    REQUIRE_FALSE(r);
    CHECK_THAT(r.error().message, Catch::Contains("--log-format"));
}

TEST_CASE("bad flags are refused with the flag's name") {
    for (auto args : {std::vector<const char*>{"g", "--bogus"}, std::vector<const char*>{"g", "--port"},
                      std::vector<const char*>{"g", "--robotraconteur-tcp-enable-ipv6=true"}}) {
        auto cmd = parse_command_line(static_cast<int>(args.size()), args.data());
        CHECK_FALSE(cmd);
    }
    const char* argv[] = {"g", "--port=99999"};
    auto cmd = parse_command_line(2, argv);
    REQUIRE(cmd);
    GatewayConfig c;
    auto r = apply_overrides(c, *cmd);
    REQUIRE_FALSE(r);
    CHECK_THAT(r.error().message, Catch::Contains("--port"));
    const char* argv2[] = {"g", "--device", "noequals"};
    auto cmd2 = parse_command_line(3, argv2);
    REQUIRE(cmd2);
    CHECK_FALSE(apply_overrides(c, *cmd2));
}

TEST_CASE("every example in gateway-config/ is a valid configuration") {
    int n = 0;
    for (const char* name : {"demo.yaml", "reynard.yaml", "lab.yaml", "usb-boards.yaml", "tls.yaml", "auth.yaml", "secure.yaml"}) {
        auto c = load_gateway_config(std::string(RR_SOURCE_DIR) + "/gateway-config/" + name);
        INFO(name);
        REQUIRE(c);
        ++n;
    }
    CHECK(n == 7);
    auto missing = load_gateway_config(std::string(RR_SOURCE_DIR) + "/gateway-config/nope.yaml");
    REQUIRE_FALSE(missing);
    CHECK_THAT(missing.error().message, Catch::Contains("cannot read"));
}

TEST_CASE("gateway.trusted_proxies and --trusted-proxy take addresses and CIDR ranges, nothing else") {
    auto c = parse_gateway_config("gateway:\n  trusted_proxies: [127.0.0.1, 10.0.0.0/8, \"::1\"]\n", "t.yaml");
    REQUIRE(c);
    CHECK(c->trusted_proxies == std::vector<std::string>{"127.0.0.1", "10.0.0.0/8", "::1"});
    auto bad = parse_gateway_config("gateway:\n  trusted_proxies: [proxy.example.org]\n", "t.yaml");
    REQUIRE_FALSE(bad);
    CHECK_THAT(bad.error().message, Catch::Contains("t.yaml:2") && Catch::Contains("gateway.trusted_proxies") &&
                                        Catch::Contains("proxy.example.org"));
    const char* argv[] = {"rr-gateway", "--trusted-proxy", "192.168.0.0/16", "--trusted-proxy=10.0.0.300"};
    auto cmd = parse_command_line(3, argv);
    REQUIRE(cmd);
    GatewayConfig g;
    REQUIRE(apply_overrides(g, *cmd));
    CHECK(g.trusted_proxies == std::vector<std::string>{"192.168.0.0/16"});
    auto cmd2 = parse_command_line(4, argv);
    REQUIRE(cmd2);
    auto applied = apply_overrides(g, *cmd2);
    REQUIRE_FALSE(applied);
    CHECK_THAT(applied.error().message, Catch::Contains("--trusted-proxy"));
}

TEST_CASE("gateway.websocket_gathered_writes: on by default, off when set false, a boolean only") {
    auto none = parse_gateway_config("gateway:\n  port: 8080\n", "t.yaml");
    REQUIRE(none);
    CHECK(none->websocket_gathered_writes);
    auto off = parse_gateway_config("gateway:\n  websocket_gathered_writes: false\n", "t.yaml");
    REQUIRE(off);
    CHECK_FALSE(off->websocket_gathered_writes);
    check_refused("gateway:\n  websocket_gathered_writes: sometimes\n", "bad.yaml:2");
}

TEST_CASE("gateway.websocket_compression: off by default, on for the listener or for paths, bad paths refused") {
    auto none = parse_gateway_config("", "t.yaml");
    REQUIRE(none);
    CHECK_FALSE(none->websocket_compression.enabled);
    CHECK(none->websocket_compression.paths.empty());
    auto all = parse_gateway_config("gateway:\n  websocket_compression:\n    enabled: true\n", "t.yaml");
    REQUIRE(all);
    CHECK(all->websocket_compression.enabled);
    auto some = parse_gateway_config("gateway:\n  websocket_compression:\n    paths: [/slow, /remote/]\n", "t.yaml");
    REQUIRE(some);
    CHECK_FALSE(some->websocket_compression.enabled);
    CHECK(some->websocket_compression.paths == std::vector<std::string>{"/slow", "/remote/"});
    auto bad = parse_gateway_config("gateway:\n  websocket_compression:\n    paths: [slow]\n", "t.yaml");
    REQUIRE_FALSE(bad);
    CHECK_THAT(bad.error().message, Catch::Contains("t.yaml:3") && Catch::Contains("gateway.websocket_compression.paths") &&
                                        Catch::Contains("\"slow\" is not a request path"));
    check_refused("gateway:\n  websocket_compression:\n    level: 9\n", "bad.yaml:3");
}

TEST_CASE("gateway.tls and the devices' TLS keys parse, incomplete TLS settings name the key") {
    auto c = parse_gateway_config(R"(
gateway:
  tls:
    certificate: /etc/rr-gateway/cert.pem
    private_key: /etc/rr-gateway/key.pem
    client_ca: /etc/rr-gateway/ca.pem
    required: true
devices:
  - name: arm
    url: rrs+tcp://arm.lab:48653/?service=robot
    tls_ca: /etc/rr-gateway/devices-ca.pem
    tls_certificate: /etc/rr-gateway/gw-client.pem
    tls_private_key: /etc/rr-gateway/gw-client.key
)", "tls.yaml");
    REQUIRE(c);
    CHECK(c->tls.enabled());
    CHECK(c->tls.certificate == "/etc/rr-gateway/cert.pem");
    CHECK(c->tls.private_key == "/etc/rr-gateway/key.pem");
    CHECK(c->tls.client_ca == "/etc/rr-gateway/ca.pem");
    CHECK(c->tls.required);
    REQUIRE(c->devices.size() == 1);
    CHECK(c->devices[0].tls_ca == "/etc/rr-gateway/devices-ca.pem");
    CHECK(c->devices[0].tls_certificate == "/etc/rr-gateway/gw-client.pem");
    CHECK(c->devices[0].tls_private_key == "/etc/rr-gateway/gw-client.key");
    CHECK_FALSE(parse_gateway_config("gateway:\n  port: 1\n", "x.yaml")->tls.enabled());

    for (auto [yaml, expect] : {
             std::pair{"gateway:\n  tls:\n    certificate: c.pem\n", "bad.yaml:3: gateway.tls.private_key: missing"},
             std::pair{"gateway:\n  tls:\n    private_key: k.pem\n", "bad.yaml:3: gateway.tls.certificate: missing"},
             std::pair{"gateway:\n  tls:\n    certificate: c.pem\n    private_key: k.pem\n    key: x\n",
                       "bad.yaml:5: gateway.tls.key: unknown key"},
             std::pair{"gateway:\n  tls:\n    certificate: c.pem\n    private_key: k.pem\n    node_certificate: n.pem\n",
                       "bad.yaml:3: gateway.tls: node_certificate and node_private_key go together"},
             std::pair{"devices:\n  - name: a\n    url: rrs+tcp://x/?service=s\n    tls_certificate: c.pem\n",
                       "bad.yaml:2: devices.a: tls_certificate and tls_private_key go together"},
         }) {
        check_refused(yaml, expect);
    }
}

TEST_CASE("TLS flags: --tls-certificate, --tls-private-key, --tls-client-ca") {
    const char* argv[] = {"g", "--tls-certificate", "c.pem", "--tls-private-key=k.pem", "--tls-client-ca", "ca.pem",
                          "--tls-required"};
    auto cmd = parse_command_line(7, argv);
    REQUIRE(cmd);
    GatewayConfig c;
    REQUIRE(apply_overrides(c, *cmd));
    CHECK(c.tls.certificate == "c.pem");
    CHECK(c.tls.private_key == "k.pem");
    CHECK(c.tls.client_ca == "ca.pem");
    CHECK(c.tls.required);
    const char* half[] = {"g", "--tls-certificate", "c.pem"};
    auto cmd2 = parse_command_line(3, half);
    REQUIRE(cmd2);
    GatewayConfig c2;
    auto r = apply_overrides(c2, *cmd2);
    REQUIRE_FALSE(r);
    CHECK_THAT(r.error().message, Catch::Contains("gateway.tls.private_key"));
}

TEST_CASE("devices: auth (shared, alias gateway | passthrough) and max_passthrough_sessions") {
    auto c = parse_gateway_config(R"(
devices:
  - name: arm
    url: rr+tcp://arm.lab:48653/?service=robot
    auth: passthrough
    max_passthrough_sessions: 5
    json_api_requires_device_login: true
  - name: cam
    url: rr+tcp://cam.lab:48653/?service=cam
  - name: door
    url: rr+tcp://door.lab:48653/?service=door
    auth: gateway
)", "auth.yaml");
    REQUIRE(c);
    REQUIRE(c->devices.size() == 3);
    CHECK(c->devices[2].auth == rr::server::gateway::DeviceAuth::shared);  // "gateway" is shared's other name
    CHECK(c->devices[0].auth == rr::server::gateway::DeviceAuth::passthrough);
    CHECK(c->devices[0].max_passthrough_sessions == 5);
    CHECK(c->devices[0].json_api_requires_device_login);
    CHECK_FALSE(c->devices[1].json_api_requires_device_login);
    CHECK(c->devices[1].auth == rr::server::gateway::DeviceAuth::shared);
    CHECK(c->devices[1].max_passthrough_sessions == 64);
    for (auto [yaml, expect] : {
             std::pair{"devices:\n  - name: a\n    url: rr+tcp://x/?service=s\n    auth: tokens\n",
                       "bad.yaml:4: devices.a.auth: expected shared (alias gateway) or passthrough, got \"tokens\""},
             std::pair{"devices:\n  - name: a\n    url: rr+tcp://x/?service=s\n    max_passthrough_sessions: 0\n",
                       "bad.yaml:4: devices.a.max_passthrough_sessions: must be at least 1"},
             std::pair{"devices:\n  - name: a\n    url: rr+tcp://x/?service=s\n    json_api_requires_device_login: true\n",
                       "bad.yaml:4: devices.a.json_api_requires_device_login: needs auth: passthrough (only a passthrough device "
                       "has logins of its own for JSON API clients)"},
             std::pair{"devices:\n  - name: a\n    url: rr+tcp://x/?service=s\n    auth: passthrough\n"
                       "    json_api_requires_device_login: maybe\n",
                       "bad.yaml:5: devices.a.json_api_requires_device_login: expected true or false"},
         }) {
        check_refused(yaml, expect);
    }
}

TEST_CASE("gateway.auth parses users, tokens, jwt, roles and limits, and bad keys are clear errors") {
    auto c = parse_gateway_config(R"(
gateway:
  auth:
    users: /etc/rr-gateway/users.txt
    tokens: /etc/rr-gateway/tokens.txt
    jwt:
      algorithm: RS256
      key: /etc/rr-gateway/idp.pem
      audience: rr-gateway
      issuer: https://idp
    roles:
      viewer:
        - allow: [read]
      driver:
        - devices: create
          members: [Drive, "Webcams[*].*"]
          allow: [call, write, lock]
    login_limit: {max_failures: 3, window_s: 10, lockout_s: 20}
    session_ttl_s: 600
)", "auth.yaml");
    REQUIRE(c);
    const auto& a = c->auth;
    CHECK(a.enabled());
    CHECK(a.users == "/etc/rr-gateway/users.txt");
    CHECK(a.tokens == "/etc/rr-gateway/tokens.txt");
    CHECK(a.jwt.algorithm == "RS256");
    CHECK(a.jwt.issuer == "https://idp");
    CHECK(a.jwt.user_claim == "sub");
    REQUIRE(a.roles.size() == 2);
    CHECK(a.roles[0].first == "viewer");
    CHECK(a.roles[0].second[0].devices == std::vector<std::string>{"*"});
    CHECK(a.roles[0].second[0].read);
    CHECK_FALSE(a.roles[0].second[0].write);
    CHECK_FALSE(a.roles[0].second[0].lock);
    CHECK(a.roles[1].second[0].devices == std::vector<std::string>{"create"});
    CHECK(a.roles[1].second[0].members == std::vector<std::string>{"Drive", "Webcams[*].*"});
    CHECK(a.roles[1].second[0].call);
    CHECK(a.roles[1].second[0].write);
    CHECK(a.roles[1].second[0].lock);
    CHECK(a.max_failures == 3);
    CHECK(a.lockout_s == 20);
    CHECK(a.session_ttl_s == 600);
    CHECK_FALSE(parse_gateway_config("gateway:\n  port: 1\n", "x.yaml")->auth.enabled());

    for (auto [yaml, expect] : {
             std::pair{"gateway:\n  auth:\n    user: u.txt\n", "bad.yaml:3: gateway.auth.user: unknown key"},
             std::pair{"gateway:\n  auth:\n    users: u.txt\n    roles:\n      r:\n        - allow: [read, delete]\n",
                       "bad.yaml:6: gateway.auth.roles.r[0].allow: \"delete\" is not read, write, call, lock or record"},
             std::pair{"gateway:\n  auth:\n    users: u.txt\n    roles:\n      r:\n        - devices: [a]\n",
                       "bad.yaml:6: gateway.auth.roles.r[0].allow: missing"},
             std::pair{"gateway:\n  auth:\n    users: u.txt\n    roles:\n      r:\n        - alow: [read]\n",
                       "bad.yaml:6: gateway.auth.roles.r[0].alow: unknown key"},
             std::pair{"gateway:\n  auth:\n    roles:\n      r:\n        - allow: [read]\n",
                       "bad.yaml:3: gateway.auth: roles but no users, tokens or jwt"},
             std::pair{"gateway:\n  auth:\n    jwt:\n      algorithm: none\n      key: k\n      audience: a\n",
                       "bad.yaml:4: gateway.auth.jwt.algorithm: \"none\" is not HS256, RS256 or ES256"},
             std::pair{"gateway:\n  auth:\n    jwt:\n      algorithm: HS256\n      key: k\n",
                       "bad.yaml:4: gateway.auth.jwt.audience: missing"},
             std::pair{"gateway:\n  auth:\n    users: u\n    login_limit: {max_failures: 0}\n",
                       "bad.yaml:4: gateway.auth.login_limit.max_failures: must be at least 1"},
             std::pair{"gateway:\n  auth:\n    users: u\n    roles:\n      \"a,b\": []\n",
                       "bad.yaml:5: gateway.auth.roles.a,b: a role name has no spaces or commas"},
         }) {
        check_refused(yaml, expect);
    }
}

TEST_CASE("gateway.auth files: the example loads, and a bad file is a configuration error naming it") {
    auto c = load_gateway_config(std::string(RR_SOURCE_DIR) + "/gateway-config/auth.yaml");
    REQUIRE(c);
    auto abs = [](std::string& p) { p = std::string(RR_SOURCE_DIR) + "/" + p; };
    abs(c->auth.users);
    abs(c->auth.tokens);
    abs(c->auth.jwt.key);
    auto a = load_gateway_auth(c->auth);
    REQUIRE(a);
    REQUIRE(*a);
    CHECK((*a)->enabled());
    CHECK((*a)->summary().users == 3);
    CHECK((*a)->policy()->role_names() == std::vector<std::string>{"dashboard", "operator", "viewer"});
    auto wall = (*a)->principal_for_user("wall");
    REQUIRE(wall);
    using rr::server::gateway::auth::Operation;
    CHECK(wall->allows("webcam", "Webcams[0].CaptureFrame", Operation::call));
    CHECK_FALSE(wall->allows("create", "Drive", Operation::call));
    CHECK(wall->allows("create", "Bumpers", Operation::read));
    CHECK_FALSE(wall->allows("create", "Bumpers", Operation::write));

    GatewayAuthConfig none;
    auto off = load_gateway_auth(none);
    REQUIRE(off);
    CHECK(*off == nullptr);

    GatewayAuthConfig bad = c->auth;
    bad.users = "/nonexistent/users.txt";
    auto r = load_gateway_auth(bad);
    REQUIRE_FALSE(r);
    CHECK(r.error().type == rr::MessageErrorType::InvalidConfiguration);
    CHECK_THAT(r.error().message, Catch::StartsWith("gateway.auth.users: ") && Catch::Contains("/nonexistent/users.txt"));
    bad = c->auth;
    bad.jwt.key = c->auth.users;  // not a PEM key
    r = load_gateway_auth(bad);
    REQUIRE_FALSE(r);
    CHECK_THAT(r.error().message, Catch::StartsWith("gateway.auth.jwt: ") && Catch::Contains("PEM"));
}

TEST_CASE("gateway.limits: defaults, values, and errors naming the key") {
    auto d = parse_gateway_config("", "empty.yaml");
    REQUIRE(d);
    CHECK(d->limits.connections_per_address == 256);
    CHECK(d->limits.messages_per_second == 0);
    CHECK(d->limits.bytes_per_second == 0);
    CHECK(d->limits.burst_s == 1);

    auto c = parse_gateway_config(R"(
gateway:
  limits:
    connections_per_address: 2
    messages_per_second: 100
    bytes_per_second: 0
    burst_s: 3
)", "limits.yaml");
    REQUIRE(c);
    CHECK(c->limits.connections_per_address == 2);
    CHECK(c->limits.messages_per_second == 100);
    CHECK(c->limits.bytes_per_second == 0);
    CHECK(c->limits.burst_s == 3);

    struct Case {
        const char* yaml;
        const char* expect;
    };
    for (auto [yaml, expect] : {
             Case{"gateway:\n  limits:\n    messages_per_second: -5\n",
                  "bad.yaml:3: gateway.limits.messages_per_second: expected a non-negative integer, got \"-5\""},
             Case{"gateway:\n  limits:\n    bytes_per_second: 10\n",
                  "bad.yaml:3: gateway.limits.bytes_per_second: must be 0 (unlimited) or at least 1024"},
             Case{"gateway:\n  limits:\n    conections_per_address: 2\n", "bad.yaml:3: gateway.limits.conections_per_address: unknown key"},
             Case{"gateway:\n  limits:\n    burst_s: 0\n", "bad.yaml:3: gateway.limits.burst_s: must be at least 1"},
             Case{"gateway:\n  limits: 5\n", "bad.yaml:2: gateway.limits: expected a mapping"},
         }) {
        check_refused(yaml, expect);
    }
}

TEST_CASE("gateway.allowed_origins: entries the Origin check can match are accepted, others are refused") {
    auto c = parse_gateway_config(R"(
gateway:
  allowed_origins: ["https://lab.example.org", "http://localhost:9090", "https://*.example.org", "https://", "*",
                    "http://[::1]:8080"]
)", "o.yaml");
    REQUIRE(c);
    CHECK(c->allowed_origins.size() == 6);
    for (auto [yaml, expect] : {
             std::pair{"gateway:\n  allowed_origins: [lab.example.org]\n", "\"lab.example.org\" is not an origin"},
             std::pair{"gateway:\n  allowed_origins: [\"https://lab.example.org/\"]\n", "\"https://lab.example.org/\" has a path"},
             std::pair{"gateway:\n  allowed_origins: [\"https://lab.example.org:99999\"]\n", "has a bad port"},
             std::pair{"gateway:\n  allowed_origins: [\"ht tp://x\"]\n", "has a bad scheme"},
             std::pair{"gateway:\n  allowed_origins: https://x\n", "expected a list of strings"},
         }) {
        auto r = parse_gateway_config(yaml, "bad.yaml");
        INFO(yaml);
        REQUIRE_FALSE(r);
        CHECK_THAT(r.error().message, Catch::StartsWith("bad.yaml:2: gateway.allowed_origins: "));
        CHECK_THAT(r.error().message, Catch::Contains(expect));
    }
}

TEST_CASE("gateway command line: --allow-origin is checked like gateway.allowed_origins") {
    const char* good[] = {"rr-gateway", "--allow-origin", "https://lab.example.org"};
    auto cmd = parse_command_line(3, good);
    REQUIRE(cmd);
    GatewayConfig c;
    REQUIRE(apply_overrides(c, *cmd));
    CHECK(c.allowed_origins == std::vector<std::string>{"https://lab.example.org"});

    const char* bad[] = {"rr-gateway", "--allow-origin", "https://lab.example.org/dashboard"};
    auto cmd2 = parse_command_line(3, bad);
    REQUIRE(cmd2);
    GatewayConfig c2;
    auto r = apply_overrides(c2, *cmd2);
    REQUIRE_FALSE(r);
    CHECK_THAT(r.error().message, Catch::StartsWith("--allow-origin: \"https://lab.example.org/dashboard\" has a path"));
}

TEST_CASE("safety: the bound, the members of named devices, per-device overrides, and errors naming the key") {
    auto empty = parse_gateway_config("", "x.yaml");
    REQUIRE(empty);
    auto d = empty->safety.for_device("arm");
    CHECK(d.hold_to_run_max == std::chrono::milliseconds(500));
    CHECK(d.standard_robot);
    CHECK(d.hold_to_run.empty());

    auto c = parse_gateway_config(R"(
safety:
  hold_to_run_max_s: 0.3
  hold_to_run:
    - {device: create, member: Drive_for, timeout_arg: duration_ms, timeout_unit: ms}
  motions:
    - {device: create, member: MoveTo, wait_arg: wait}
    - {device: create, member: Dance}
  streams:
    - {device: create, member: velocity}
  stops:
    - {device: create, member: StopAll}
    - {device: create, member: mode, value: 0}
devices:
  - name: create
    url: rr+tcp://localhost:1/?service=create
  - name: arm
    url: rr+tcp://localhost:2/?service=robot
    safety: {hold_to_run_max_s: 0.2, standard_robot: false}
)", "x.yaml");
    REQUIRE(c);
    auto create = c->safety.for_device("create");
    CHECK(create.hold_to_run_max == std::chrono::milliseconds(300));
    REQUIRE(create.hold_to_run.size() == 1);
    CHECK(create.hold_to_run[0].member == "Drive_for");
    CHECK(create.hold_to_run[0].timeout_arg == "duration_ms");
    CHECK(create.hold_to_run[0].unit_s == 0.001);
    REQUIRE(create.motions.size() == 2);
    CHECK(create.motions[0].wait_arg == "wait");
    CHECK(create.motions[1].wait_arg.empty());
    REQUIRE(create.streams.size() == 1);
    REQUIRE(create.stops.size() == 2);
    CHECK_FALSE(create.stops[0].value);
    CHECK(create.stops[1].value == 0.0);
    auto arm = c->safety.for_device("arm");
    CHECK(arm.hold_to_run_max == std::chrono::milliseconds(200));
    CHECK_FALSE(arm.standard_robot);
    CHECK(arm.hold_to_run.empty());  // the members named are create's

    check_refused("safety: {hold_to_run_max_s: 60}\n", "bad.yaml:1: safety.hold_to_run_max_s: expected seconds between 0.05 and 10");
    check_refused("safety: {hold_to_run_max_s: 0}\n", "bad.yaml:1: safety.hold_to_run_max_s:");
    check_refused("safety: {hold_to_run: 3}\n", "bad.yaml:1: safety.hold_to_run: expected a list");
    check_refused("safety:\n  hold_to_run:\n    - {device: a, member: b}\n", "bad.yaml:3: safety.hold_to_run[0].timeout_arg: missing");
    check_refused("safety:\n  streams:\n    - {member: b}\n", "bad.yaml:3: safety.streams[0].device: missing");
    check_refused("safety:\n  stops:\n    - {device: a, member: b, value: halt}\n", "bad.yaml:3: safety.stops[0].value: expected a number");
    check_refused("safety:\n  hold_to_run:\n    - {device: a, member: b, timeout_arg: t, timeout_unit: h}\n",
                  "bad.yaml:3: safety.hold_to_run[0].timeout_unit: expected s or ms");
    check_refused("safety: {bound: 1}\n", "bad.yaml:1: safety.bound: unknown key");
    check_refused("devices:\n  - name: a\n    url: rr+tcp://h:1/?service=a\n    safety: {max: 1}\n", "bad.yaml:4: devices.a.safety.max: unknown key");
}
