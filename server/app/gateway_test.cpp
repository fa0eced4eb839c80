// The assembled Gateway with a device node: health endpoints, metrics, and RR through the gateway.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <thread>

#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>

#include <cstdlib>

#include "server/app/gateway.hpp"
#include "server/client/client.hpp"
#include "server/app/demo_starter.hpp"
#include "server/gateway/json_api_installer.hpp"
#include "server/service/password_table.hpp"
#include "server/service/test_raw_service.hpp"
#include "server/transport/local/local_test_support.hpp"
#include "server/transport/tcp_listener.hpp"
#include "test/support/eventually.hpp"
#include "test/support/skip.hpp"

using namespace rr;
using namespace rr::server;
using namespace rr::server::app;
using namespace std::chrono_literals;
namespace beast = boost::beast;
namespace bhttp = boost::beast::http;

namespace {

bhttp::response<bhttp::string_body> gateway_http_get(std::uint16_t port, const std::string& target,
                                                     const std::string& address = "127.0.0.1") {
    boost::asio::io_context io;
    beast::tcp_stream s(io);
    s.connect(boost::asio::ip::tcp::endpoint(boost::asio::ip::make_address(address), port));
    bhttp::request<bhttp::string_body> req{bhttp::verb::get, target, 11};
    req.set(bhttp::field::host, "localhost");
    bhttp::write(s, req);
    beast::flat_buffer b;
    bhttp::response<bhttp::string_body> res;
    bhttp::read(s, b, res);
    return res;
}

// HEAD: the parser must not wait for the body the Content-Length announces.
bhttp::response<bhttp::string_body> http_head(std::uint16_t port, const std::string& target) {
    boost::asio::io_context io;
    beast::tcp_stream s(io);
    s.connect(boost::asio::ip::tcp::endpoint(boost::asio::ip::make_address("127.0.0.1"), port));
    bhttp::request<bhttp::string_body> req{bhttp::verb::head, target, 11};
    req.set(bhttp::field::host, "localhost");
    bhttp::write(s, req);
    beast::flat_buffer b;
    bhttp::response_parser<bhttp::string_body> parser;
    parser.skip(true);
    bhttp::read(s, b, parser);
    return parser.release();
}

bhttp::response<bhttp::string_body> http_get_bearer(std::uint16_t port, const std::string& target, const std::string& token) {
    boost::asio::io_context io;
    beast::tcp_stream s(io);
    s.connect(boost::asio::ip::tcp::endpoint(boost::asio::ip::make_address("127.0.0.1"), port));
    bhttp::request<bhttp::string_body> req{bhttp::verb::get, target, 11};
    req.set(bhttp::field::host, "localhost");
    req.set(bhttp::field::authorization, "Bearer " + token);
    bhttp::write(s, req);
    beast::flat_buffer b;
    bhttp::response<bhttp::string_body> res;
    bhttp::read(s, b, res);
    return res;
}

// Whether this host has IPv6 loopback (a container may have none).
bool ipv6_loopback() {
    boost::asio::io_context io;
    boost::asio::ip::tcp::acceptor a(io);
    boost::system::error_code ec;
    a.open(boost::asio::ip::tcp::v6(), ec);
    if (!ec) a.bind(boost::asio::ip::tcp::endpoint(boost::asio::ip::address_v6::loopback(), 0), ec);
    return !ec;
}

bool tcp_connects(const std::string& address, std::uint16_t port) {
    boost::asio::io_context io;
    boost::asio::ip::tcp::socket s(io);
    boost::system::error_code ec;
    s.connect(boost::asio::ip::tcp::endpoint(boost::asio::ip::make_address(address), port), ec);
    return !ec;
}

// The port of a demo device's URL (rr+tcp://127.0.0.1:PORT/?service=…).
std::uint16_t url_port(const std::string& url) {
    const auto colon = url.rfind(':', url.find("/?"));
    return static_cast<std::uint16_t>(std::stoul(url.substr(colon + 1)));
}

DemoStarter demo_starter() {
    return [](const std::shared_ptr<Node>& node, std::uint16_t demo_port, const DemoLogin& login) {
        return app::start_demo_devices_for_gateway(*node, demo_port, login);
    };
}

}  // namespace

TEST_CASE("gateway health endpoints follow the required devices") {
    auto device = Node::create(NodeOptions{NodeID(), "dev.node", 2, {}, 0, 5000ms});
    REQUIRE(device->register_service(std::make_shared<rr::server::testing::RawTestService>()));
    // Reserve a port for the device, but start listening only later: the gateway starts not ready.
    auto probe = Node::create(NodeOptions{NodeID(), "probe", 1, {}, 0, 5000ms});
    const auto port = *listen_tcp(probe, "127.0.0.1", 0);
    probe->shutdown();

    GatewayConfig cfg;
    cfg.local = false;  // tests run side by side: no shared NodeName on this computer
    cfg.port = 0;
    cfg.listen = "127.0.0.1";
    cfg.demo = false;
    gateway::DeviceConfig d;
    d.name = "dev";
    d.url = "rr+tcp://127.0.0.1:" + std::to_string(port) + "/?service=svc";
    d.backoff_initial = 100ms;
    d.backoff_max = 200ms;
    cfg.devices.push_back(d);
    auto gw = Gateway::start(cfg);
    REQUIRE(gw);
    const auto gport = (*gw)->port();

    CHECK(gateway_http_get(gport, "/livez").result() == bhttp::status::ok);
    auto notready = gateway_http_get(gport, "/readyz");
    CHECK(notready.result() == bhttp::status::service_unavailable);
    CHECK_THAT(notready.body(), Catch::Contains("dev:"));

    REQUIRE(listen_tcp(device, "127.0.0.1", port));
    rr::testing::eventually([&] { return (*gw)->ready(); });
    REQUIRE((*gw)->ready());
    CHECK(gateway_http_get(gport, "/readyz").result() == bhttp::status::ok);

    auto metrics = gateway_http_get(gport, "/metrics");
    CHECK(metrics.result() == bhttp::status::ok);
    // The Prometheus text format's content type, also for HEAD (which had 404 text/plain, issue 15).
    CHECK(metrics[bhttp::field::content_type] == "text/plain; version=0.0.4; charset=utf-8");
    auto head = http_head(gport, "/metrics");
    CHECK(head.result() == bhttp::status::ok);
    CHECK(head[bhttp::field::content_type] == "text/plain; version=0.0.4; charset=utf-8");
    CHECK(head.body().empty());
    CHECK(std::stoul(std::string(head[bhttp::field::content_length])) > 0);
    CHECK_THAT(metrics.body(), Catch::Contains("rr_gateway_device_up{device=\"dev\",state=\"connected\"} 1"));
    CHECK_THAT(metrics.body(), Catch::Contains("rr_gateway_request_duration_seconds_bucket{device=\"dev\",le=\"+Inf\"}"));
    CHECK_THAT(metrics.body(), Catch::Contains("rr_gateway_connections "));
    (*gw)->stop();
    device->shutdown();
}

// Issue 40: as an official server node, the gateway takes both IP families on one socket (`::` with
// IPV6_V6ONLY off), and so does its demo node, except while gateway.auth is on (its services then need
// a login only the gateway has: it stays on loopback). Announces: test/interop/discovery_netns.py.
TEST_CASE("gateway: the default listen address takes IPv4 and IPv6 on one port, as does the demo node without logins") {
    if (!ipv6_loopback()) RR_SKIP("no IPv6 loopback (::1) here: the dual-stack listening cannot be checked");
    GatewayConfig cfg;  // listen: the default
    REQUIRE(cfg.listen == "::");
    cfg.local = false;  // tests run side by side: no shared NodeName on this computer
    cfg.port = 0;
    cfg.discovery.enabled = false;  // this test is about the listening sockets
    auto gw = Gateway::start(cfg, demo_starter(), gateway::install_json_api);
    INFO((gw ? std::string() : gw.error().message));
    REQUIRE(gw);
    const auto port = (*gw)->port();
    CHECK(gateway_http_get(port, "/livez").result() == bhttp::status::ok);  // IPv4 on the IPv6 socket
    CHECK(gateway_http_get(port, "/livez", "::1").result() == bhttp::status::ok);
    // The demo devices are reached over 127.0.0.1 (IPv4), and the demo node takes IPv6 too.
    rr::testing::eventually([&] { return (*gw)->ready(); });
    REQUIRE((*gw)->ready());
    const auto demo_port = url_port((*gw)->device("create")->config().url);
    CHECK(tcp_connects("127.0.0.1", demo_port));
    CHECK(tcp_connects("::1", demo_port));
    (*gw)->stop();

    // With gateway.auth the demo node stays on loopback (IPv4), whatever the gateway listens on.
    const auto dir = std::filesystem::temp_directory_path() / ("rr_gw_dual_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "tokens.txt") << "dual-stack-test-token-0123456789 wall viewer\n";
    cfg.auth.tokens = (dir / "tokens.txt").string();
    auto secured = Gateway::start(cfg, demo_starter(), gateway::install_json_api);
    INFO((secured ? std::string() : secured.error().message));
    REQUIRE(secured);
    CHECK(gateway_http_get((*secured)->port(), "/livez", "::1").result() == bhttp::status::ok);
    rr::testing::eventually([&] { return (*secured)->ready(); });
    REQUIRE((*secured)->ready());
    const auto secured_demo = url_port((*secured)->device("create")->config().url);
    CHECK(tcp_connects("127.0.0.1", secured_demo));
    CHECK_FALSE(tcp_connects("::1", secured_demo));
    (*secured)->stop();
    std::filesystem::remove_all(dir);
}

TEST_CASE("a gateway that cannot listen fails to start and says why") {
    auto holder = Node::create(NodeOptions{NodeID(), "holder", 1, {}, 0, 5000ms});
    const auto port = *listen_tcp(holder, "127.0.0.1", 0);
    GatewayConfig cfg;
    cfg.local = false;  // tests run side by side: no shared NodeName on this computer
    cfg.port = port;
    cfg.listen = "127.0.0.1";
    cfg.demo = false;
    auto gw = Gateway::start(cfg);
    REQUIRE_FALSE(gw);
    CHECK(gw.error().type == MessageErrorType::IOError);
    CHECK_THAT(gw.error().message, Catch::Contains(std::to_string(port)));
}

TEST_CASE("gateway: serves rr+local under its NodeName (and the demo node under NAME.demo), a second gateway with that name is refused") {
    // This process's node directories in a temporary tree (root uses the system dirs, others the user dirs).
    local::testing::TempNodeDirs tmp;
    for (const auto& [var, dir] : {std::pair{"ROBOTRACONTEUR_SYSTEM_RUN_DIR", tmp.dirs.system_run_dir},
                                   {"ROBOTRACONTEUR_SYSTEM_STATE_DIR", tmp.dirs.system_state_dir},
                                   {"ROBOTRACONTEUR_SYSTEM_CONFIG_DIR", tmp.dirs.system_config_dir},
                                   {"ROBOTRACONTEUR_USER_RUN_DIR", tmp.dirs.user_run_dir},
                                   {"ROBOTRACONTEUR_USER_CONFIG_DIR", tmp.dirs.user_config_dir}})
        REQUIRE(::setenv(var, dir.c_str(), 1) == 0);

    auto device = Node::create(NodeOptions{NodeID(), "dev.node", 2, {}, 0, 5000ms});
    REQUIRE(device->register_service(std::make_shared<rr::server::testing::RawTestService>()));
    const auto port = *listen_tcp(device, "127.0.0.1", 0);

    const std::string name = local::testing::unique_node_name("gwtest");
    GatewayConfig cfg;
    cfg.local = true;
    cfg.node_name = name;
    cfg.port = 0;
    cfg.listen = "127.0.0.1";
    cfg.demo = true;
    gateway::DeviceConfig d;
    d.name = "dev";
    d.url = "rr+tcp://127.0.0.1:" + std::to_string(port) + "/?service=svc";
    cfg.devices.push_back(d);
    DemoStarter demo = demo_starter();
    auto gw = Gateway::start(cfg, demo);
    REQUIRE(gw);
    rr::testing::eventually([&] { return (*gw)->ready(); });
    REQUIRE((*gw)->ready());

    client::IoThreads io(1);
    for (const std::string& url : {"rr+local:///?nodename=" + name + "&service=dev",
                                  "rr+local:///?nodeid=" + (*gw)->node()->node_id().to_string() + "&service=dev"}) {
        INFO(url);
        auto c = client::Client::connect(io.executor(), url);
        INFO((c ? std::string() : c.error().message));
        REQUIRE(c);
        auto x = (*c)->root().get("x");
        REQUIRE(x);
        CHECK(*x == Value::scalar(42.5));
        CHECK((*c)->close_wait().ok());
    }

    // The demo devices' own node, by its NodeName.
    auto demo_client = client::Client::connect(io.executor(), "rr+local:///?nodename=" + name + ".demo&service=create");
    INFO((demo_client ? std::string() : demo_client.error().message));
    REQUIRE(demo_client);
    CHECK((*demo_client)->root().type() == "experimental.create.Create");
    CHECK((*demo_client)->close_wait().ok());

    auto second = Gateway::start(cfg, demo);
    REQUIRE_FALSE(second);
    CHECK_THAT(second.error().message, Catch::Contains(name) && Catch::Contains("--no-local"));

    (*gw)->stop();
    // The names are free again once the first gateway is gone.
    cfg.devices.clear();
    auto third = Gateway::start(cfg, demo);
    INFO((third ? std::string() : third.error().message));
    REQUIRE(third);
    (*third)->stop();

    // gateway.local: false (--no-local): no rr+local entry or socket under the gateway's NodeName, and
    // none for its demo node; a local client finds nothing.
    cfg.local = false;
    auto quiet = Gateway::start(cfg, demo);
    INFO((quiet ? std::string() : quiet.error().message));
    REQUIRE(quiet);
    rr::testing::eventually([&] { return (*quiet)->ready(); });
    REQUIRE((*quiet)->ready());
    // (The run directories hold the by-nodename / by-nodeid entries and sockets. The NodeID cache and
    // the NodeName lock files, nodeids/NAME.pid, of the earlier gateways stay, as the official node's do.)
    for (const auto& run_dir : {tmp.dirs.system_run_dir, tmp.dirs.user_run_dir}) {
        if (!std::filesystem::exists(run_dir)) continue;
        for (const auto& f : std::filesystem::recursive_directory_iterator(run_dir)) {
            if (f.path().parent_path().filename() == "nodeids") continue;
            INFO(f.path().string());
            CHECK(f.path().filename().string().find(name) == std::string::npos);
            CHECK_FALSE(f.is_socket());
        }
    }
    CHECK_FALSE(client::Client::connect(io.executor(), "rr+local:///?nodename=" + name + ".demo&service=create"));
    (*quiet)->stop();
    device->shutdown();
}

TEST_CASE("gateway: with gateway.auth the demo node requires a login only the gateway knows") {
    const auto dir = std::filesystem::temp_directory_path() / ("rr_gw_demo_login_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    const std::string token = "demo-login-test-token-0123456789";
    {
        std::ofstream(dir / "users.txt") << "alice " << PasswordTable::md5_hex("alice-pw") << " operator\n";
        std::ofstream(dir / "tokens.txt") << token << " wall operator\n";
    }
    GatewayConfig cfg;
    cfg.local = false;  // tests run side by side: no shared NodeName on this computer (rr+local: demo_node_logins.py)
    cfg.port = 0;
    cfg.listen = "127.0.0.1";
    cfg.demo = true;
    cfg.auth.users = (dir / "users.txt").string();
    cfg.auth.tokens = (dir / "tokens.txt").string();
    cfg.auth.roles.push_back({"operator", {GatewayAuthConfig::Rule{{"*"}, {"*"}, true, true, true}}});

    auto gw = Gateway::start(cfg, demo_starter(), gateway::install_json_api);
    INFO((gw ? std::string() : gw.error().message));
    REQUIRE(gw);
    // Ready: the gateway's own sessions logged in to the demo devices.
    rr::testing::eventually([&] { return (*gw)->ready(); });
    REQUIRE((*gw)->ready());

    auto create = (*gw)->device("create");
    REQUIRE(create);
    const auto login = create->config();
    CHECK(login.username == "rr-gateway-demo");
    REQUIRE(login.password.size() == 64);
    CHECK(login.password.find_first_not_of("0123456789abcdef") == std::string::npos);
    REQUIRE((*gw)->device("webcam"));
    CHECK((*gw)->device("webcam")->config().password == login.password);
    for (const auto& name : (*gw)->demo_node()->service_names()) {
        INFO(name);
        CHECK((*gw)->demo_node()->find_service(name)->requires_authentication());
    }
    // GET /api/features needs no login (the dashboard asks it first) and says logins are on.
    auto features = gateway_http_get((*gw)->port(), "/api/features");
    CHECK(features.result() == bhttp::status::ok);
    CHECK(features.body() == "{\"auth\":true,\"discovery\":true}\n");  // JSON answers end with a newline
    CHECK_FALSE((*gw)->demo_discovery());  // the demo node stays quiet while logins are on

    client::IoThreads io(1);
    // Straight to the demo node: no credentials, a made-up password, a gateway user's password.
    for (const auto& [user, password] : {std::pair<std::string, std::string>{"", ""},
                                         {"rr-gateway-demo", std::string(64, 'a')},
                                         {"alice", "alice-pw"}}) {
        INFO("user \"" << user << "\"");
        client::ClientOptions o;
        o.username = user;
        o.password = password;
        auto c = client::Client::connect(io.executor(), login.url, o);
        REQUIRE_FALSE(c);
        CHECK(c.error().type == MessageErrorType::AuthenticationError);
        CHECK(c.error().message.find(login.password) == std::string::npos);
    }
    // (The right one works: the refusals above are the login's, not an unreachable node's.)
    {
        client::ClientOptions o;
        o.username = login.username;
        o.password = login.password;
        auto c = client::Client::connect(io.executor(), login.url, o);
        INFO((c ? std::string() : c.error().message));
        REQUIRE(c);
        CHECK((*c)->close_wait().ok());
    }

    // Through the gateway: a gateway user reads a demo device's property.
    {
        client::ClientOptions o;
        o.username = "alice";
        o.password = "alice-pw";
        auto c = client::Client::connect(io.executor(), "rr+tcp://127.0.0.1:" + std::to_string((*gw)->port()) + "/?service=create", o);
        INFO((c ? std::string() : c.error().message));
        REQUIRE(c);
        auto d = (*c)->root().get("DistanceTraveled");
        INFO((d ? std::string() : d.error().message));
        CHECK(d);
        CHECK((*c)->close_wait().ok());
    }

    // The JSON API works on the demo devices, and no answer carries the demo node's password.
    for (const std::string target : {"/api/devices", "/api/devices/create", "/api/devices/create/properties/DistanceTraveled",
                                     "/metrics"}) {
        INFO(target);
        auto res = http_get_bearer((*gw)->port(), target, token);
        CHECK(res.result() == bhttp::status::ok);
        CHECK(res.body().find(login.password) == std::string::npos);
    }

    // A second gateway draws another password.
    auto other = Gateway::start(cfg, demo_starter());
    REQUIRE(other);
    CHECK((*other)->device("create")->config().password != login.password);
    (*other)->stop();

    // A demo starter that leaves its services open while logins are on: the gateway does not start.
    DemoStarter careless = [](const std::shared_ptr<Node>& node, std::uint16_t demo_port, const DemoLogin&) {
        return app::start_demo_devices_for_gateway(*node, demo_port);
    };
    auto refused = Gateway::start(cfg, careless);
    REQUIRE_FALSE(refused);
    CHECK_THAT(refused.error().message, Catch::Contains("does not require a login while gateway.auth is on"));

    // Without gateway.auth nothing changes: the demo node stays open (documented).
    cfg.auth = GatewayAuthConfig{};
    auto open = Gateway::start(cfg, demo_starter());
    REQUIRE(open);
    CHECK((*open)->device("create")->config().username.empty());
    CHECK((*open)->device("create")->config().password.empty());
    rr::testing::eventually([&] { return (*open)->ready(); });
    REQUIRE((*open)->ready());
    auto anon = client::Client::connect(io.executor(), (*open)->device("create")->config().url);
    INFO((anon ? std::string() : anon.error().message));
    REQUIRE(anon);
    CHECK((*anon)->close_wait().ok());
    (*open)->stop();

    (*gw)->stop();
    std::filesystem::remove_all(dir);
}
