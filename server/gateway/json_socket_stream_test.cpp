// The JSON WebSocket while a pipe streams large packets: the gateway's demo webcam (320x240 RGB frames,
// about 1 MB of JSON each, 10 per second) streams to a JSON subscriber, and requests to the same device
// must still be answered. Turning a frame into JSON takes about a second under ASan; done on the device
// connection's strand, it held every reply from the device behind the frames queued before it (10 s
// and more: RequestTimeout).
#include "server/app/demo_starter.hpp"
#include "server/gateway/json_api_test_fixture.hpp"

using namespace rr;
using namespace rr::server;
using namespace rr::server::gateway;
using namespace rr::server::gateway::testing;

namespace {

json webcam(std::string op, std::string m, json more = json::object()) {
    more["op"] = std::move(op);
    more["device"] = "webcam";
    more["object"] = "Webcams[0]";
    more["member"] = std::move(m);
    return more;
}

}  // namespace

// [timing]: it asserts how long each request takes while the frames stream.
TEST_CASE("json socket: requests to a device are answered while its pipe streams camera frames", "[timing]") {
    app::GatewayConfig cfg;
    cfg.local = false;  // tests run side by side: no shared NodeName on this computer
    cfg.port = 0;
    cfg.listen = "127.0.0.1";
    cfg.demo = true;
    cfg.threads = 2;
    std::shared_ptr<JsonSocketServer> sockets;
    auto g = app::Gateway::start(cfg, [](const std::shared_ptr<Node>& node, std::uint16_t port, const app::DemoLogin& login) { return app::start_demo_devices_for_gateway(*node, port, login); }, [&](http::HttpServer& http, const auto& devices, std::shared_ptr<auth::GatewayAuth>) {
        auto api = std::make_shared<JsonApi>(devices);
        sockets = install_json_socket(http, api);
        return api;
    });
    REQUIRE(g);
    auto& gw = **g;
    auto cam = gw.device("webcam");
    REQUIRE(cam);
    const auto until = std::chrono::steady_clock::now() + 30s;
    while (cam->status().state != DeviceState::connected && std::chrono::steady_clock::now() < until)
        std::this_thread::sleep_for(10ms);
    REQUIRE(cam->status().state == DeviceState::connected);

    {
        WsClient ws(gw.port());
        auto sub = ws.request(webcam("subscribe", "FrameStream"));
        INFO(sub.dump());
        REQUIRE(sub.contains("result"));
        const auto sid = sub["result"]["subscription"].get<std::uint64_t>();
        REQUIRE(ws.request(webcam("call", "StartStreaming")).contains("result"));
        auto frame = ws.wait_push([sid](const json& j) { return j.value("subscription", std::uint64_t{0}) == sid; }, 60s);
        REQUIRE(frame);
        CHECK((*frame)["kind"] == "pipe");
        CHECK((*frame)["value"]["width"] == 320);
        CHECK((*frame)["value"]["data"].size() == 320u * 240u * 3u);

        // Asked on a second socket: on the streaming one a reply also waits behind the frames already
        // queued for that client (this client parses each one slowly under ASan). Generous bounds (ASan
        // on a loaded machine), far below what frames queued ahead of the device's replies cost.
        WsClient other(gw.port());
        auto timed = [&](const json& request) {
            const auto t0 = std::chrono::steady_clock::now();
            auto r = other.request(request, 60s);
            const auto took = std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - t0);
            INFO(request.dump() << " took " << took.count() << " ms: " << r.dump().substr(0, 200));
            CHECK(took < 5s);
            return r;
        };
        for (int i = 0; i < 3; ++i) {
            std::this_thread::sleep_for(1s);  // frames keep arriving meanwhile
            CHECK(timed(webcam("get", "Name"))["result"] == json{{"value", "Left"}});
        }
        CHECK(timed(webcam("call", "StopStreaming")).contains("result"));
    }
    sockets.reset();
    gw.stop();
}
