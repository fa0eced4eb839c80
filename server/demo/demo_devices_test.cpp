// The demo devices over the wire (loopback TCP, entry-level RawClient): demo_starter() on a node;
// Create: Drive, properties, the Bump event, the packets wire, play_callback on the streaming client;
// webcam: objref paths, FrameStream frames, CaptureFrameToBuffer + memory read, and backpressure (a
// client that stops reading gets frames skipped, the device never blocks).
// Time is simulated (advance() / tick()) where the test checks values.
#include <catch2/catch.hpp>

#include <condition_variable>
#include <deque>
#include <future>
#include <thread>

#include "base/message/error_entry.hpp"
#include "core/session/elements.hpp"
#include "core/value/pack_value.hpp"
#include "server/client/raw_client.hpp"
#include "server/demo/demo_devices.hpp"
#include "server/transport/tcp_listener.hpp"
#include "test/support/eventually.hpp"

using namespace rr;
using namespace rr::server;
using namespace rr::server::demo;
using namespace std::chrono_literals;

namespace {

class Inbox {
public:
    void push(MessageEntry e) {
        {
            std::lock_guard lock(mutex_);
            entries_.push_back(std::move(e));
        }
        cv_.notify_all();
    }
    std::optional<MessageEntry> take(MessageEntryType type, std::string_view member, std::chrono::milliseconds timeout = 30s) {
        std::unique_lock lock(mutex_);
        std::optional<MessageEntry> out;
        cv_.wait_for(lock, timeout, [&] {
            for (auto it = entries_.begin(); it != entries_.end(); ++it)
                if (it->entry_type == type && it->member_name == member) {
                    out = std::move(*it);
                    entries_.erase(it);
                    return true;
                }
            return false;
        });
        return out;
    }
    std::vector<MessageEntry> take_all(MessageEntryType type) {
        std::lock_guard lock(mutex_);
        std::vector<MessageEntry> out;
        for (auto it = entries_.begin(); it != entries_.end();)
            if (it->entry_type == type) {
                out.push_back(std::move(*it));
                it = entries_.erase(it);
            } else {
                ++it;
            }
        return out;
    }

private:
    std::mutex mutex_;
    std::condition_variable cv_;
    std::deque<MessageEntry> entries_;
};

struct Client {
    std::shared_ptr<RawClient> raw;
    std::shared_ptr<Inbox> inbox = std::make_shared<Inbox>();

    Result<MessageEntry> call(MessageEntry e) const {
        std::promise<Result<MessageEntry>> p;
        raw->request(std::move(e), [&](Result<MessageEntry> r) { p.set_value(std::move(r)); });
        auto f = p.get_future();
        REQUIRE(f.wait_for(30s) == std::future_status::ready);
        return f.get();
    }
    MessageEntry ok(MessageEntry e) const {
        auto r = call(std::move(e));
        REQUIRE(r);
        if (r->error != MessageErrorType::None) FAIL("error reply: " << entry_error(*r)->message);
        return std::move(*r);
    }
};

Client connect(boost::asio::any_io_executor ex, std::uint16_t port, const std::string& service) {
    Client c;
    auto url = parse_connection_url("rr+tcp://127.0.0.1:" + std::to_string(port) + "/?service=" + service);
    REQUIRE(url);
    std::promise<Result<std::shared_ptr<RawClient>>> p;
    RawClient::connect(
        ex, *url, {}, [inbox = c.inbox](MessageEntry&& e) { inbox->push(std::move(e)); }, {},
        [&](Result<std::shared_ptr<RawClient>> r) { p.set_value(std::move(r)); });
    auto f = p.get_future();
    REQUIRE(f.wait_for(30s) == std::future_status::ready);
    auto r = f.get();
    INFO((r ? std::string() : r.error().message));
    REQUIRE(r);
    c.raw = *r;
    return c;
}

MessageEntry req(MessageEntryType type, std::string path, std::string member) {
    MessageEntry e;
    e.entry_type = type;
    e.service_path = std::move(path);
    e.member_name = std::move(member);
    return e;
}

MessageEntry drive(std::int16_t v, std::int16_t r) {
    auto e = req(MessageEntryType::FunctionCallReq, "create", "Drive");
    e.elements.push_back(make_scalar_element<std::int16_t>("velocity", v));
    e.elements.push_back(make_scalar_element<std::int16_t>("radius", r));
    return e;
}

template <class T>
T scalar(const MessageEntry& e, std::string_view name) {
    const auto* el = e.find(name);
    REQUIRE(el);
    T v{};
    REQUIRE(read_scalar(*el, v));
    return v;
}

/// Unpacks element `name` of `e` as the type of member `member` of `object`.
Value unpack_member_value(const ServiceObject& object, std::string_view member, const MessageElement& el) {
    const auto* def = object.definition().find_member(member);
    REQUIRE(def);
    const auto service = object.type().substr(0, object.type().rfind('.'));
    auto v = unpack_value(el, def->type, object.types()->set(), service);
    INFO((v ? std::string() : v.error().message));
    REQUIRE(v);
    return std::move(*v);
}

std::vector<std::uint8_t> bytes_of(const Value& v) {
    const auto* a = v.get_if<NumericArray>();
    REQUIRE(a);
    return {a->view<std::uint8_t>().begin(), a->view<std::uint8_t>().end()};
}

std::int32_t le_i32(const std::vector<std::uint8_t>& d, std::size_t off) {
    return static_cast<std::int32_t>(std::uint32_t(d.at(off)) | std::uint32_t(d.at(off + 1)) << 8 |
                                     std::uint32_t(d.at(off + 2)) << 16 | std::uint32_t(d.at(off + 3)) << 24);
}

struct NodeFixture {
    std::shared_ptr<Node> node;
    std::uint16_t port = 0;
    NodeFixture() {
        NodeOptions o;
        o.threads = 2;
        node = Node::create(o);
        auto p = listen_tcp(node, "127.0.0.1", 0);
        REQUIRE(p);
        port = *p;
    }
    ~NodeFixture() { node->shutdown(); }
};

}  // namespace

TEST_CASE("demo starter: registers create and webcam on the demo node and returns their loopback URLs") {
    NodeFixture f;
    REQUIRE(start_demo_devices(*f.node));
    auto configs = demo_device_urls(f.port);
    REQUIRE(configs.size() == 2);
    const std::string base = "rr+tcp://127.0.0.1:" + std::to_string(f.port) + "/?service=";
    CHECK(configs[0].service == "create");
    CHECK(configs[0].url == base + "create");
    CHECK(configs[1].service == "webcam");
    CHECK(configs[1].url == base + "webcam");
    auto names = f.node->service_names();
    CHECK(std::find(names.begin(), names.end(), "create") != names.end());
    CHECK(std::find(names.begin(), names.end(), "webcam") != names.end());

    // A second start on the same node fails (names taken) and leaves the first one working.
    CHECK_FALSE(start_demo_devices(*f.node));

    auto c = connect(f.node->io_context().get_executor(), f.port, "create");
    auto dist = c.ok(req(MessageEntryType::PropertyGetReq, "create", "DistanceTraveled"));
    CHECK(scalar<std::int32_t>(dist, "value") == 0);
    c.ok(drive(100, 32767));
    // The timer runs the simulation in real time: the distance grows.
    std::int32_t d = 0;
    CHECK(rr::testing::eventually([&] {
        d = scalar<std::int32_t>(c.ok(req(MessageEntryType::PropertyGetReq, "create", "DistanceTraveled")), "value");
        return d > 0;
    }, rr::testing::kHangBound, 20ms));
    c.ok(drive(0, 32767));

    auto w = connect(f.node->io_context().get_executor(), f.port, "webcam");
    auto name = w.ok(req(MessageEntryType::PropertyGetReq, "webcam.Webcams[1]", "Name"));
    REQUIRE(name.find("value"));
    CHECK(read_string(*name.find("value")) == "Right");
    auto missing = w.call(req(MessageEntryType::PropertyGetReq, "webcam.Webcams[2]", "Name"));
    REQUIRE(missing);
    CHECK(missing->error == MessageErrorType::ObjectNotFound);
    c.raw->close();
    w.raw->close();
}

TEST_CASE("demo create over the wire: Drive, properties, Bump, packets wire, play_callback") {
    NodeFixture f;
    auto devices = make_demo_devices();
    REQUIRE(devices);
    auto& dev = *devices->create;
    REQUIRE(f.node->register_service(devices->create_service));
    auto c = connect(f.node->io_context().get_executor(), f.port, "create");

    auto bad = c.call(drive(600, 32767));
    REQUIRE(bad);
    CHECK(bad->error == MessageErrorType::InvalidArgument);
    c.ok(drive(300, 32767));
    CHECK(dev.state().velocity == 300);

    c.ok(req(MessageEntryType::WireConnectReq, "create", "packets"));
    auto first = c.inbox->take(MessageEntryType::WirePacket, "packets");
    REQUIRE(first);  // the value set at start
    c.ok(req(MessageEntryType::FunctionCallReq, "create", "StartStreaming"));
    CHECK(dev.streaming());

    for (int i = 0; i < 250; ++i) dev.advance(20ms);  // 5 s: the wall is 1335 mm away

    auto bump = c.inbox->take(MessageEntryType::EventReq, "Bump");
    REQUIRE(bump);
    CHECK(bump->service_path == "create");
    auto cb = c.inbox->take(MessageEntryType::CallbackCallReq, "play_callback");
    REQUIRE(cb);
    CHECK(scalar<std::int32_t>(*cb, "DistanceTraveled") == 1335);
    CHECK(scalar<std::int32_t>(*cb, "AngleTraveled") == 0);
    MessageEntry ret = req(MessageEntryType::CallbackCallRet, cb->service_path, cb->member_name);
    ret.request_id = cb->request_id;
    const std::vector<std::uint8_t> song = {60, 32, 64, 16};
    ret.elements.push_back(make_array_element<std::uint8_t>("return", song));
    c.raw->send(std::move(ret));
    rr::testing::eventually([&] { return dev.play_stats().replies != 0; });
    CHECK(dev.play_stats().replies == 1);
    CHECK(dev.play_stats().last_song == song);

    CHECK(scalar<std::int32_t>(c.ok(req(MessageEntryType::PropertyGetReq, "create", "DistanceTraveled")), "value") == 1335);
    CHECK(scalar<std::uint8_t>(c.ok(req(MessageEntryType::PropertyGetReq, "create", "Bumpers")), "value") == 3);
    CHECK(scalar<std::int32_t>(c.ok(req(MessageEntryType::PropertyGetReq, "create", "AngleTraveled")), "value") == 0);

    // Spin: the angle grows counter-clockwise.
    c.ok(drive(129, 1));
    for (int i = 0; i < 50; ++i) dev.advance(20ms);  // 1 s at 1 rad/s
    CHECK(scalar<std::int32_t>(c.ok(req(MessageEntryType::PropertyGetReq, "create", "AngleTraveled")), "value") == 57);

    // Packets came at 20 Hz of simulated time (the wire keeps the newest per client, so count the
    // sequence numbers instead); the newest shows the robot at the wall and the song.
    CHECK(dev.packet_sequence() == 121);  // one at StartStreaming, then every 50 ms for 6 s
    // The newest packet is the one numbered 121 (its bytes 2-3): wait until it has arrived.
    std::vector<std::uint8_t> data;
    const bool newest = rr::testing::eventually([&] {
        for (const auto& e : c.inbox->take_all(MessageEntryType::WirePacket)) {
            const auto* pe = e.find("packet");
            REQUIRE(pe);
            const Value packet = unpack_member_value(*dev.object(), "packets", *pe);
            auto d = bytes_of(*packet.field("Data"));
            REQUIRE(d.size() == kSensorDataSize);
            if ((d[2] | (d[3] << 8)) == 121) data = std::move(d);
        }
        return !data.empty();
    });
    REQUIRE(newest);
    CHECK(le_i32(data, 4) == 1335);
    CHECK(le_i32(data, 12) == 1335);
    CHECK(data[34] == 4);
    CHECK(data[35] == 60);

    c.ok(req(MessageEntryType::FunctionCallReq, "create", "StopStreaming"));
    CHECK_FALSE(dev.streaming());
    for (int i = 0; i < 50; ++i) dev.advance(20ms);
    CHECK(dev.packet_sequence() == 121);
    c.raw->close();
    devices->create_service->shutdown();
}

TEST_CASE("demo create: a bump during an outstanding play_callback is played when that call returns") {
    NodeFixture f;
    DemoOptions opts;
    opts.create.play_period = 1000ms;
    auto devices = make_demo_devices(opts);
    REQUIRE(devices);
    auto& dev = *devices->create;
    REQUIRE(f.node->register_service(devices->create_service));
    auto c = connect(f.node->io_context().get_executor(), f.port, "create");
    c.ok(req(MessageEntryType::FunctionCallReq, "create", "StartStreaming"));
    c.ok(drive(300, 32767));

    // 1 s: the periodic call, left unanswered; the wall (1335 mm away) is hit at 4.45 s.
    for (int i = 0; i < 230; ++i) dev.advance(20ms);  // 4.6 s
    auto periodic = c.inbox->take(MessageEntryType::CallbackCallReq, "play_callback");
    REQUIRE(periodic);
    CHECK(scalar<std::int32_t>(*periodic, "DistanceTraveled") == 300);
    REQUIRE(c.inbox->take(MessageEntryType::EventReq, "Bump"));
    CHECK_FALSE(c.inbox->take(MessageEntryType::CallbackCallReq, "play_callback", 100ms));

    MessageEntry ret = req(MessageEntryType::CallbackCallRet, periodic->service_path, periodic->member_name);
    ret.request_id = periodic->request_id;
    ret.elements.push_back(make_array_element<std::uint8_t>("return", std::vector<std::uint8_t>{60, 8}));
    c.raw->send(std::move(ret));
    rr::testing::eventually([&] { return dev.play_stats().replies != 0; });
    REQUIRE(dev.play_stats().replies == 1);

    // The next step (4.62 s, before the 5 s period) makes the bump's call, at the wall.
    dev.advance(20ms);
    auto at_wall = c.inbox->take(MessageEntryType::CallbackCallReq, "play_callback");
    REQUIRE(at_wall);
    CHECK(scalar<std::int32_t>(*at_wall, "DistanceTraveled") == 1335);
    CHECK(dev.play_stats().calls == 2);
    c.raw->close();
    devices->create_service->shutdown();
}

TEST_CASE("demo webcam over the wire: frames on FrameStream, memories, backpressure") {
    NodeFixture f;
    auto devices = make_demo_devices();
    REQUIRE(devices);
    auto& host = *devices->webcam;
    auto& cam = *host.camera(0);
    REQUIRE(f.node->register_service(devices->webcam_service));
    const std::string path = "webcam.Webcams[0]";

    auto c = connect(f.node->io_context().get_executor(), f.port, "webcam");
    auto pc = req(MessageEntryType::PipeConnectReq, path, "FrameStream");
    pc.elements.push_back(make_scalar_element<std::int32_t>("index", -1));
    const auto index = scalar<std::int32_t>(c.ok(std::move(pc)), "index");
    host.tick();  // not streaming yet: no frame
    c.ok(req(MessageEntryType::FunctionCallReq, path, "StartStreaming"));
    for (int i = 0; i < 3; ++i) host.tick();
    for (std::uint64_t n = 2; n <= 4; ++n) {
        auto p = c.inbox->take(MessageEntryType::PipePacket, "FrameStream");
        REQUIRE(p);
        const auto* ep = p->find(std::to_string(index));
        REQUIRE(ep);
        const MessageElement* pk = nullptr;
        for (const auto& sub : ep->elements)
            if (sub.name == "packet") pk = &sub;
        REQUIRE(pk);
        const Value image = unpack_member_value(*cam.object(), "FrameStream", *pk);
        CHECK(*image.field("width")->as<std::int32_t>() == 320);
        CHECK(*image.field("height")->as<std::int32_t>() == 240);
        CHECK(*image.field("step")->as<std::int32_t>() == 960);
        CHECK(bytes_of(*image.field("data")) == render_webcam_frame(0, n).data);
    }
    CHECK(cam.stats().frames_sent == 3);

    // CaptureFrameToBuffer, then read a block of `buffer` and of `multidimbuffer`.
    auto size = c.ok(req(MessageEntryType::FunctionCallReq, path, "CaptureFrameToBuffer"));
    REQUIRE(size.find("return"));
    const auto frame = render_webcam_frame(0, 4);
    auto mr = req(MessageEntryType::MemoryRead, path, "buffer");
    mr.elements.push_back(make_scalar_element<std::uint64_t>("memorypos", 1000));
    mr.elements.push_back(make_scalar_element<std::uint64_t>("count", 500));
    auto block = c.ok(std::move(mr));
    REQUIRE(block.find("data"));
    CHECK(read_array<std::uint8_t>(*block.find("data")) ==
          std::vector<std::uint8_t>(frame.data.begin() + 1000, frame.data.begin() + 1500));

    // Backpressure: a second client streams, then stops reading (its io_context stops). Frames for it
    // are skipped once more than max_backlog_bytes wait; tick() never blocks.
    c.raw->close();
    boost::asio::io_context slow_io;
    auto guard = boost::asio::make_work_guard(slow_io);
    std::thread slow_thread([&] { slow_io.run(); });
    auto slow = connect(slow_io.get_executor(), f.port, "webcam");
    auto spc = req(MessageEntryType::PipeConnectReq, path, "FrameStream");
    spc.elements.push_back(make_scalar_element<std::int32_t>("index", -1));
    slow.ok(std::move(spc));
    slow.ok(req(MessageEntryType::FunctionCallReq, path, "StartStreaming"));
    slow_io.stop();
    slow_thread.join();
    const auto before = cam.stats();
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < 2000 && cam.stats().frames_skipped == before.frames_skipped; ++i) host.tick();
    const auto stats = cam.stats();
    CHECK(stats.frames_skipped > before.frames_skipped);
    CHECK(stats.frames_sent > before.frames_sent);  // the first frames were queued
    CHECK(std::chrono::steady_clock::now() - t0 < 30s);
    // Ticking on: every frame is skipped now, none queued.
    for (int i = 0; i < 5; ++i) host.tick();
    CHECK(cam.stats().frames_sent == stats.frames_sent);
    CHECK(cam.stats().frames_skipped == stats.frames_skipped + 5);

    // Let the slow client drain and close.
    slow_io.restart();
    std::thread drain([&] { slow_io.run(); });
    slow.raw->close();
    slow.raw.reset();
    guard.reset();
    f.node->shutdown();
    slow_io.stop();
    drain.join();
    devices->webcam_service->shutdown();
}
