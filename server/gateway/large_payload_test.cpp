// Multi-MiB payloads end to end (issue 14's zero-copy path): large arrays are read into their frame's
// final buffer (read_space), written with gathered writes that outrun the socket buffer (the
// asynchronous rest of a partial write), forwarded by the gateway without a copy of the payload, and
// fanned out as one shared encoding. Every byte must arrive as sent, on rr+tcp, rr+ws and through the
// gateway.
#include <catch2/catch.hpp>

#include <thread>

#include "server/client/client.hpp"
#include "server/gateway/device_mirror.hpp"
#include "server/http/http_server.hpp"
#include "server/node/node.hpp"
#include "server/node/test_node.hpp"
#include "server/service/object_service.hpp"
#include "server/service/wire_member.hpp"
#include "server/transport/tcp_listener.hpp"

using namespace rr;
using namespace rr::server;
using namespace std::chrono_literals;
using rr::client::Client;
using rr::server::testing::test_node;

namespace {

constexpr const char* kLargeDef =
    "service example.large\n\nstdver 0.10\n\nobject Obj\n    function double[] echo(double[] d)\n"
    "    wire uint8[] frame [readonly]\nend\n";

struct LargeDevice {
    std::shared_ptr<Node> node = test_node("large.device");
    std::shared_ptr<http::HttpServer> http;  // kept alive: the listener holds it weakly
    std::shared_ptr<WireMember> frame;
    std::uint16_t port = 0;

    LargeDevice() {
        auto types = ServiceTypes::create({kLargeDef});
        REQUIRE(types);
        auto root = ServiceObject::create(*types, "example.large.Obj");
        REQUIRE(root);
        REQUIRE((*root)->set_function("echo", [](const SessionRef&, std::vector<Value> a) -> Result<Value> {
            return std::move(a[0]);
        }));
        auto wire = (*root)->wire("frame");
        REQUIRE(wire);
        frame = *wire;
        auto service = ObjectService::create("svc", *root);
        REQUIRE(service);
        REQUIRE(node->register_service(*service));
        http = std::make_shared<http::HttpServer>(node, http::HttpOptions{});
        TcpListenerOptions tcp;
        tcp.http = http::http_handler(http);
        auto p = listen_tcp(node, "127.0.0.1", 0, std::move(tcp));
        REQUIRE(p);
        port = *p;
    }
    ~LargeDevice() { node->shutdown(); }
};

// 1 Mi doubles (8 MiB), every one distinct, so a misplaced or repeated piece shows.
Value large_array(double offset) {
    std::vector<double> d(1 << 20);
    for (std::size_t i = 0; i < d.size(); ++i) d[i] = offset + static_cast<double>(i) * 0.25;
    return Value::array<double>(std::span<const double>(d));
}

std::shared_ptr<Client> connect_client(rr::client::IoThreads& io, const std::string& url) {
    // Bounds on a hang (a WebSocket handshake to an ASan node took over the 5 s default at load 40;
    // an 8 MiB echo under such a load takes longer than the default 15 s per request).
    rr::client::ClientOptions o;
    o.connect_timeout = 60s;
    o.request_timeout = 120s;
    o.receive_timeout = 60s;
    auto c = Client::connect(io.executor(), url, o);
    INFO(url << ": " << (c ? std::string() : c.error().message));
    REQUIRE(c);
    return *c;
}

void echo_large_twice(Client& c) {
    for (double offset : {1.0, -7.5}) {
        const Value sent = large_array(offset);
        auto got = c.root().call("echo", {sent});
        INFO((got ? std::string() : got.error().message));
        REQUIRE(got);
        CHECK(*got == sent);
    }
}

}  // namespace

TEST_CASE("large payloads: an 8 MiB array round-trips intact over rr+tcp and rr+ws") {
    LargeDevice device;
    rr::client::IoThreads io{2};
    for (std::string scheme : {"rr+tcp", "rr+ws"}) {
        INFO(scheme);
        auto c = connect_client(io, scheme + "://127.0.0.1:" + std::to_string(device.port) + "/?service=svc");
        echo_large_twice(*c);
        REQUIRE(c->close_wait());
    }
}

TEST_CASE("large payloads: through the gateway, requests and replies forwarded, a wire value fanned out") {
    LargeDevice device;
    auto gateway_node = test_node("large.gateway");
    gateway::DeviceConfig cfg;
    cfg.name = "dev";
    cfg.url = "rr+tcp://127.0.0.1:" + std::to_string(device.port) + "/?service=svc";
    auto mirror = gateway::DeviceMirror::create(gateway_node, cfg);
    REQUIRE(mirror);
    (*mirror)->start();
    auto port = listen_tcp(gateway_node, "127.0.0.1", 0);
    REQUIRE(port);
    for (int i = 0; i < 500 && (*mirror)->status().state != gateway::DeviceState::connected; ++i)
        std::this_thread::sleep_for(10ms);
    REQUIRE((*mirror)->status().state == gateway::DeviceState::connected);

    rr::client::IoThreads io{2};
    const std::string url = "rr+tcp://127.0.0.1:" + std::to_string(*port) + "/?service=dev";
    auto a = connect_client(io, url);
    auto b = connect_client(io, url);
    echo_large_twice(*a);

    // One 4 MiB frame to two clients: one encoding shared by both sessions' writes.
    auto wa = a->root().wire_connect("frame");
    auto wb = b->root().wire_connect("frame");
    REQUIRE(wa);
    REQUIRE(wb);
    std::vector<std::uint8_t> pixels(4 << 20);
    for (std::size_t i = 0; i < pixels.size(); ++i) pixels[i] = static_cast<std::uint8_t>(i * 13 + i / 251);
    const Value frame = Value::array<std::uint8_t>(std::span<const std::uint8_t>(pixels));
    const auto is_frame = [&](const auto& v) { return v.value == frame; };
    const auto before_a = wa->values_received(), before_b = wb->values_received();
    REQUIRE(device.frame->set_out_value(frame));
    auto got_a = wa->wait_value(is_frame, 10s, before_a);
    auto got_b = wb->wait_value(is_frame, 10s, before_b);
    INFO((got_a ? std::string() : got_a.error().message));
    CHECK(got_a);
    CHECK(got_b);

    REQUIRE(a->close_wait());
    REQUIRE(b->close_wait());
    (*mirror)->stop();
    gateway_node->shutdown();
}
