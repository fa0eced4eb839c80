// The assembled Gateway with a device node: health endpoints, metrics, and RR through the gateway.
#include <catch2/catch.hpp>

#include <thread>

#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>

#include "server/app/gateway.hpp"
#include "server/service/test_raw_service.hpp"

using namespace rr;
using namespace rr::server;
using namespace rr::server::app;
using namespace std::chrono_literals;
namespace beast = boost::beast;
namespace bhttp = boost::beast::http;

namespace {

bhttp::response<bhttp::string_body> http_get(std::uint16_t port, const std::string& target) {
    boost::asio::io_context io;
    beast::tcp_stream s(io);
    s.connect(boost::asio::ip::tcp::endpoint(boost::asio::ip::make_address("127.0.0.1"), port));
    bhttp::request<bhttp::string_body> req{bhttp::verb::get, target, 11};
    req.set(bhttp::field::host, "localhost");
    bhttp::write(s, req);
    beast::flat_buffer b;
    bhttp::response<bhttp::string_body> res;
    bhttp::read(s, b, res);
    return res;
}

}  // namespace

TEST_CASE("gateway health endpoints follow the required devices") {
    auto device = Node::create(NodeOptions{NodeID(), "dev.node", 2, {}, 0, 5000ms});
    REQUIRE(device->register_service(std::make_shared<testing::RawTestService>()));
    // Reserve a port for the device, but start listening only later: the gateway starts not ready.
    auto probe = Node::create(NodeOptions{NodeID(), "probe", 1, {}, 0, 5000ms});
    const auto port = *probe->listen_tcp("127.0.0.1", 0);
    probe->shutdown();

    GatewayConfig cfg;
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

    CHECK(http_get(gport, "/livez").result() == bhttp::status::ok);
    auto notready = http_get(gport, "/readyz");
    CHECK(notready.result() == bhttp::status::service_unavailable);
    CHECK_THAT(notready.body(), Catch::Contains("dev:"));

    REQUIRE(device->listen_tcp("127.0.0.1", port));
    for (int i = 0; i < 300 && !(*gw)->ready(); ++i) std::this_thread::sleep_for(10ms);
    REQUIRE((*gw)->ready());
    CHECK(http_get(gport, "/readyz").result() == bhttp::status::ok);

    auto metrics = http_get(gport, "/metrics");
    CHECK(metrics.result() == bhttp::status::ok);
    CHECK_THAT(metrics.body(), Catch::Contains("rr_gateway_device_up{device=\"dev\",state=\"connected\"} 1"));
    CHECK_THAT(metrics.body(), Catch::Contains("rr_gateway_request_duration_seconds_bucket{device=\"dev\",le=\"+Inf\"}"));
    CHECK_THAT(metrics.body(), Catch::Contains("rr_gateway_connections "));
    (*gw)->stop();
    device->shutdown();
}

TEST_CASE("a gateway that cannot listen fails to start and says why") {
    auto holder = Node::create(NodeOptions{NodeID(), "holder", 1, {}, 0, 5000ms});
    const auto port = *holder->listen_tcp("127.0.0.1", 0);
    GatewayConfig cfg;
    cfg.port = port;
    cfg.listen = "127.0.0.1";
    cfg.demo = false;
    auto gw = Gateway::start(cfg);
    REQUIRE_FALSE(gw);
    CHECK(gw.error().type == MessageErrorType::IOError);
    CHECK_THAT(gw.error().message, Catch::Contains(std::to_string(port)));
}
