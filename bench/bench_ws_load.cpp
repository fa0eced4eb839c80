// rr_bench_ws_load: a Beast WebSocket load generator for the gateway's JSON API (docs/json-api.md,
// subprotocol rr-gateway.json.v1). One thread, one io_context, N connections.
//
// Usage:
//   rr_bench_ws_load --port P --clients N fanout [--seconds S] [--device D] [--member M] [--hz H] [--binary]
//       each client subscribes to wire M of device D (default bench / Ticks, whose values are
//       [stamp_us, sequence, ...]); after every client has its first value, values are counted for
//       S seconds (default 5). Prints one JSON line: delivered values/s (all clients), the expected
//       rate N × H, the fraction of the values the device sent in each client's window that reached
//       it (delivered_of_sent; below 1: coalesced, as wires keep only the newest value), latency
//       from the device's stamp to arrival (p50/p99/max µs), the load generator's own CPU%, and the
//       bytes received per value, and per-client rates (min, median). --binary subscribes with
//       "binary": true (binary pushes: the array arrives as raw bytes, read in place); --member Frames
//       (uint8[] camera frames, rr_bench_service --frame-hz) needs --binary.
//   rr_bench_ws_load --port P --clients N idle
//       opens N connections (no subscription), prints {"opened": N, …} and keeps them open until a
//       line (or EOF) arrives on stdin, so that the caller can read the gateway's RSS meanwhile.
//   --slow K --read-delay-ms D: the first K clients wait D ms before each read (slow consumers); the
//       row's figures are the other clients', and "slow" holds theirs.
//   --max-rate-hz R: subscribes with "max_rate_hz": R (docs/json-api.md "Rate and queue length"); the
//       row's expected_per_s is then N × min(H, R).
//   --deflate: the clients offer permessage-deflate (the gateway compresses when its configuration
//       allows it: gateway.websocket_compression); the row says whether it was negotiated.
//   --foxglove: the clients are Foxglove WebSocket clients (docs/foxglove.md: /foxglove, subprotocol
//       foxglove.websocket.v1) subscribed to the channel `D/M`; the values are the messageData payloads
//       ({"value": [stamp_us, sequence, ...], "time": …}).
// Connections are opened at most 64 at a time (the gateway's listen backlog is finite).
#include <cstring>
#include <deque>
#include <iostream>
#include <memory>
#include <string>
#include <thread>

#include <unistd.h>

#include <boost/asio/connect.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/posix/stream_descriptor.hpp>
#include <boost/asio/read_until.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/streambuf.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>

#include "bench/bench_common.hpp"
#include "server/gateway/binary_push.hpp"

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using clock_type = std::chrono::steady_clock;

namespace {

constexpr const char* kJsonSubprotocol = "rr-gateway.json.v1";
constexpr const char* kFoxgloveSubprotocol = "foxglove.websocket.v1";
constexpr std::size_t kMaxConnecting = 64;

struct Stats {
    bool measuring = false;
    std::size_t with_value = 0;     // clients that received at least one value
    std::size_t opened = 0, failed = 0;
    std::uint64_t delivered = 0;    // values counted while measuring
    std::uint64_t bytes = 0;        // message bytes received while measuring
    std::vector<double> latency_us; // while measuring
    std::vector<double> slow_latency_us;  // of the slow clients (--slow), kept apart
    std::string first_error;
};

class Connection : public std::enable_shared_from_this<Connection> {
public:
    /// `read_delay`: wait that long before each read (a slow consumer; zero: read at once).
    Connection(asio::io_context& io, Stats& stats, std::function<void()> on_open_done,
               std::chrono::milliseconds read_delay = {})
        : ws_(io), stats_(stats), on_open_done_(std::move(on_open_done)), read_delay_(read_delay), delay_(io) {}

    /// Foxglove WebSocket instead of the JSON API: subscribes to the channel of this topic once advertised.
    void foxglove(std::string topic) { foxglove_topic_ = std::move(topic); }
    /// Offers permessage-deflate in the handshake.
    void offer_deflate() {
        websocket::permessage_deflate pmd;
        pmd.client_enable = true;
        ws_.set_option(pmd);
    }
    /// Whether the handshake's response accepted permessage-deflate.
    bool deflated() const { return deflated_; }

    void open(tcp::endpoint endpoint, std::string host, std::optional<nlohmann::json> subscribe) {
        subscribe_ = std::move(subscribe);
        if (!foxglove_topic_.empty()) subscribe_.reset();
        auto self = shared_from_this();
        beast::get_lowest_layer(ws_).async_connect(endpoint, [self, host](beast::error_code ec) {
            if (ec) return self->failed("connect: " + ec.message());
            beast::get_lowest_layer(self->ws_).socket().set_option(tcp::no_delay(true));
            const bool fox = !self->foxglove_topic_.empty();
            self->ws_.set_option(websocket::stream_base::decorator([fox](websocket::request_type& req) {
                req.set(beast::http::field::sec_websocket_protocol, fox ? kFoxgloveSubprotocol : kJsonSubprotocol);
            }));
            self->ws_.async_handshake(self->response_, host, fox ? "/foxglove" : "/", [self](beast::error_code ec) {
                if (ec) return self->failed("handshake: " + ec.message());
                self->deflated_ = self->response_[beast::http::field::sec_websocket_extensions].find("permessage-deflate") !=
                                  beast::string_view::npos;
                ++self->stats_.opened;
                self->opened_ = true;
                self->opened_done();
                if (self->subscribe_) {
                    self->out_ = self->subscribe_->dump();
                    self->ws_.text(true);
                    self->ws_.async_write(asio::buffer(self->out_), [self](beast::error_code ec, std::size_t) {
                        if (ec) self->failed("subscribe: " + ec.message());
                    });
                }
                self->read();
            });
        });
    }

    /// Values the device sent while this client was measuring (sequence numbers first..last seen).
    double sent_span() const { return first_seq_ < 0 ? 0 : last_seq_ - first_seq_ + 1; }
    /// Values this client received while measuring.
    std::uint64_t delivered() const { return delivered_; }
    bool opened() const { return opened_; }
    bool slow() const { return read_delay_.count() > 0; }

    void close() {
        beast::error_code ec;
        beast::get_lowest_layer(ws_).socket().close(ec);
    }

private:
    void opened_done() {
        if (on_open_done_) std::exchange(on_open_done_, nullptr)();
    }
    void failed(const std::string& what) {
        if (stats_.first_error.empty()) stats_.first_error = what;
        if (on_open_done_) ++stats_.failed;
        opened_done();
    }
    void read() {
        auto self = shared_from_this();
        ws_.async_read(buffer_, [self](beast::error_code ec, std::size_t n) {
            if (ec) return;
            const auto data = self->buffer_.data();
            const std::string_view bytes(static_cast<const char*>(data.data()), data.size());
            if (self->ws_.got_binary())
                self->on_binary(bytes);
            else
                self->on_message(bytes);
            if (self->stats_.measuring && !self->slow()) self->stats_.bytes += n;
            self->buffer_.consume(self->buffer_.size());
            if (!self->slow()) return self->read();
            self->delay_.expires_after(self->read_delay_);
            self->delay_.async_wait([self](beast::error_code ec) {
                if (!ec) self->read();
            });
        });
    }
    void on_message(std::string_view text) {
        const double now = rr::bench::wall_clock_us();
        auto msg = nlohmann::json::parse(text, nullptr, false);
        if (!foxglove_topic_.empty()) return on_foxglove_text(msg);
        if (msg.is_discarded() || msg.value("kind", "") != "wire") return;
        const auto& v = msg["value"];
        if (!v.is_array() || v.size() < 2 || v[1].get<double>() < 0) return;
        on_value(now, v[0].get<double>(), v[1].get<double>());
    }
    // Foxglove: subscribe once the topic's channel is advertised.
    void on_foxglove_text(const nlohmann::json& msg) {
        if (subscribed_ || msg.is_discarded() || msg.value("op", "") != "advertise" || !msg["channels"].is_array()) return;
        for (const auto& c : msg["channels"]) {
            if (c.value("topic", "") != foxglove_topic_) continue;
            subscribed_ = true;
            out_ = nlohmann::json{{"op", "subscribe"}, {"subscriptions", {{{"id", 1}, {"channelId", c["id"]}}}}}.dump();
            ws_.text(true);
            auto self = shared_from_this();
            ws_.async_write(asio::buffer(out_), [self](beast::error_code ec, std::size_t) {
                if (ec) self->failed("subscribe: " + ec.message());
            });
            return;
        }
    }
    // Foxglove messageData: 0x01, subscription id, receive time, then the channel's JSON message.
    void on_foxglove_binary(double now, std::string_view m) {
        if (m.size() <= 13 || m[0] != 0x01) return;
        auto msg = nlohmann::json::parse(m.substr(13), nullptr, false);
        if (msg.is_discarded() || !msg.is_object() || !msg["value"].is_array()) return;
        const auto& v = msg["value"];
        if (v.size() < 2 || !v[0].is_number() || !v[1].is_number()) return;
        on_value(now, v[0].get<double>(), v[1].get<double>());
    }
    // A binary push (docs/json-api.md "Binary pushes"): the stamp and sequence straight from the array
    // (a double[] such as Ticks, or a uint8[] frame whose first 16 bytes are those two doubles).
    void on_binary(std::string_view m) {
        const double now = rr::bench::wall_clock_us();
        if (!foxglove_topic_.empty()) return on_foxglove_binary(now, m);
        auto parts = rr::server::gateway::split_binary_push(m);
        if (!parts) return;
        auto msg = nlohmann::json::parse(parts->json_text, nullptr, false);
        if (msg.is_discarded() || msg.value("kind", "") != "wire" || !msg["value"].is_object()) return;
        const auto& ref = msg["value"];
        const std::size_t at = ref.value("offset", std::size_t{0});
        const std::string type = ref.value("type", "");
        const bool stamped = (type == "double" && ref.value("length", 0) >= 2) || (type == "uint8" && ref.value("length", 0) >= 16);
        if (!stamped || at + 16 > parts->arrays.size()) return;
        double v[2];
        std::memcpy(v, parts->arrays.data() + at, 16);
        on_value(now, v[0], v[1]);
    }
    void on_value(double now, double stamp_us, double seq) {
        if (seq < 0) return;
        if (!got_value_) {
            got_value_ = true;
            ++stats_.with_value;
        }
        if (!stats_.measuring) return;
        if (first_seq_ < 0) first_seq_ = seq;
        last_seq_ = seq;
        ++delivered_;
        if (slow()) return stats_.slow_latency_us.push_back(now - stamp_us);
        ++stats_.delivered;
        stats_.latency_us.push_back(now - stamp_us);
    }

    websocket::stream<beast::tcp_stream> ws_;
    Stats& stats_;
    std::function<void()> on_open_done_;
    std::chrono::milliseconds read_delay_;
    asio::steady_timer delay_;
    std::optional<nlohmann::json> subscribe_;
    std::string foxglove_topic_;  // "" = the JSON API
    bool subscribed_ = false;
    beast::flat_buffer buffer_;
    std::string out_;
    bool got_value_ = false, opened_ = false;
    double first_seq_ = -1, last_seq_ = -1;
    std::uint64_t delivered_ = 0;
    websocket::response_type response_;
    bool deflated_ = false;
};

}  // namespace

int main(int argc, char** argv) {
    std::uint16_t port = 0;
    std::size_t clients = 10;
    double seconds = 5, hz = 100;
    std::string mode, device = "bench", member = "Ticks";
    bool binary = false, foxglove = false, deflate = false;
    double max_rate_hz = 0;
    std::size_t slow = 0;
    long read_delay_ms = 0;
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        auto value = [&]() -> std::string { return i + 1 < argc ? argv[++i] : ""; };
        if (a == "--port") port = static_cast<std::uint16_t>(std::stoi(value()));
        else if (a == "--clients") clients = std::stoul(value());
        else if (a == "--seconds") seconds = std::stod(value());
        else if (a == "--hz") hz = std::stod(value());
        else if (a == "--device") device = value();
        else if (a == "--member") member = value();
        else if (a == "--binary") binary = true;
        else if (a == "--foxglove") foxglove = true;
        else if (a == "--deflate") deflate = true;
        else if (a == "--max-rate-hz") max_rate_hz = std::stod(value());
        else if (a == "--slow") slow = std::stoul(value());
        else if (a == "--read-delay-ms") read_delay_ms = std::stol(value());
        else if (a == "fanout" || a == "idle") mode = a;
        else {
            std::cerr << "usage: " << argv[0]
                      << " --port P --clients N (fanout [--seconds S] [--hz H] [--binary | --foxglove] [--slow K --read-delay-ms D] | idle)\n";
            return 2;
        }
    }
    if (port == 0 || mode.empty()) {
        std::cerr << "need --port and a mode (fanout | idle)\n";
        return 2;
    }
    rr::bench::raise_fd_limit();

    asio::io_context io;
    Stats stats;
    const tcp::endpoint endpoint(asio::ip::make_address("127.0.0.1"), port);
    const std::string host = "127.0.0.1:" + std::to_string(port);
    std::optional<nlohmann::json> subscribe;
    if (mode == "fanout")
        subscribe = nlohmann::json{{"id", 1}, {"op", "subscribe"}, {"device", device}, {"member", member}, {"binary", binary}};
    if (subscribe && max_rate_hz > 0) (*subscribe)["max_rate_hz"] = max_rate_hz;

    // Open the connections, at most kMaxConnecting in progress.
    std::vector<std::shared_ptr<Connection>> conns;
    std::size_t next = 0, in_progress = 0;
    std::function<void()> pump = [&] {
        while (next < clients && in_progress < kMaxConnecting) {
            ++in_progress;
            ++next;
            const bool is_slow = next <= slow && read_delay_ms > 0;  // the first K clients
            auto c = std::make_shared<Connection>(io, stats, [&] {
                --in_progress;
                pump();
            }, std::chrono::milliseconds(is_slow ? read_delay_ms : 0));
            conns.push_back(c);
            if (foxglove && mode == "fanout") c->foxglove(device + "/" + member);
            if (deflate) c->offer_deflate();
            c->open(endpoint, host, subscribe);
        }
    };
    const auto open_t0 = clock_type::now();
    pump();
    while (stats.opened + stats.failed < clients) io.run_one();
    const double open_s = rr::bench::elapsed_us(open_t0, clock_type::now()) / 1e6;

    if (mode == "idle") {
        std::cout << nlohmann::json{{"mode", "idle"}, {"clients", clients}, {"opened", stats.opened},
                                    {"failed", stats.failed}, {"open_s", open_s}, {"error", stats.first_error}}
                         .dump()
                  << std::endl;
        // Serve the sockets (pings, closes) until the caller writes a line or closes stdin.
        asio::posix::stream_descriptor in(io, ::dup(0));
        asio::streambuf line;
        bool done = false;
        asio::async_read_until(in, line, '\n', [&](beast::error_code, std::size_t) { done = true; });
        while (!done) io.run_one();
        for (auto& c : conns) c->close();
        return 0;
    }

    // fanout: wait (at most 30 s) until every open client has its first value, then measure.
    const auto wait_until = clock_type::now() + std::chrono::seconds(30);
    while (stats.with_value < stats.opened && clock_type::now() < wait_until) io.run_for(std::chrono::milliseconds(10));
    stats.latency_us.reserve(static_cast<std::size_t>(double(clients) * hz * seconds * 1.2));
    const auto cpu0 = rr::bench::CpuSnapshot::now();
    stats.measuring = true;
    const auto t0 = clock_type::now();
    io.run_for(std::chrono::duration_cast<clock_type::duration>(std::chrono::duration<double>(seconds)));
    stats.measuring = false;
    const double wall = rr::bench::elapsed_us(t0, clock_type::now());
    const auto cpu1 = rr::bench::CpuSnapshot::now();
    double device_sent = 0, slow_sent = 0;  // per client: values the device sent in its window (wires keep the newest only)
    std::vector<double> per_client, slow_per_client;
    std::size_t deflated = 0;
    for (auto& c : conns) {
        deflated += c->deflated() ? 1 : 0;
        (c->slow() ? slow_sent : device_sent) += c->sent_span();
        if (c->opened()) (c->slow() ? slow_per_client : per_client).push_back(double(c->delivered()) * 1e6 / wall);
        c->close();
    }
    std::sort(per_client.begin(), per_client.end());
    nlohmann::json slow_row;  // the slow clients apart: what the gateway does for a consumer that falls behind
    if (!slow_per_client.empty()) {
        const auto& l = stats.slow_latency_us;
        slow_row = {{"clients", slow_per_client.size()},
                    {"read_delay_ms", read_delay_ms},
                    {"per_client_per_s_median", rr::bench::percentile(slow_per_client, 0.5)},
                    {"delivered_of_sent", slow_sent > 0 ? double(l.size()) / slow_sent : 0.0},
                    {"p50_us", rr::bench::percentile(l, 0.5)},
                    {"p99_us", rr::bench::percentile(l, 0.99)},
                    {"max_us", l.empty() ? 0.0 : *std::max_element(l.begin(), l.end())}};
    }
    std::cout << nlohmann::json{{"mode", "fanout"},
                                {"clients", clients},
                                {"opened", stats.opened},
                                {"failed", stats.failed},
                                {"with_value", stats.with_value},
                                {"open_s", open_s},
                                {"seconds", wall / 1e6},
                                {"delivered_per_s", double(stats.delivered) * 1e6 / wall},
                                {"expected_per_s", double(per_client.size()) * (max_rate_hz > 0 ? std::min(hz, max_rate_hz) : hz)},
                                {"max_rate_hz", max_rate_hz},
                                {"deflated_clients", deflated},
                                {"delivered_of_sent", device_sent > 0 ? double(stats.delivered) / device_sent : 0.0},
                                {"per_client_per_s_min", per_client.empty() ? 0.0 : per_client.front()},
                                {"per_client_per_s_median", rr::bench::percentile(per_client, 0.5)},
                                {"p50_us", rr::bench::percentile(stats.latency_us, 0.5)},
                                {"p99_us", rr::bench::percentile(stats.latency_us, 0.99)},
                                {"max_us", stats.latency_us.empty() ? 0.0
                                                                    : *std::max_element(stats.latency_us.begin(), stats.latency_us.end())},
                                {"loadgen_cpu_pct", 100.0 * (cpu1.cpu_us - cpu0.cpu_us) / wall},
                                {"loadgen_cpu_us_per_value", stats.delivered ? (cpu1.cpu_us - cpu0.cpu_us) / double(stats.delivered) : 0.0},
                                {"loadgen_vcsw_per_value", stats.delivered ? double(cpu1.vcsw - cpu0.vcsw) / double(stats.delivered) : 0.0},
                                {"member", member},
                                {"binary", binary},
                                {"foxglove", foxglove},
                                {"slow", slow_row},
                                {"bytes_per_value", stats.delivered ? double(stats.bytes) / double(stats.delivered) : 0.0},
                                {"error", stats.first_error}}
                     .dump()
              << std::endl;
    return 0;
}
