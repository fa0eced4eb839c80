// Test fixture for the JSON API: rr_interop_service (test/interop) as the device, behind a Gateway
// started with the JSON API, plus small HTTP and WebSocket clients.
#pragma once

#include <functional>
#include <filesystem>
#include <catch2/catch.hpp>

#include <condition_variable>
#include <csignal>
#include <deque>
#include <mutex>
#include <optional>
#include <spawn.h>
#include <sys/wait.h>
#include <thread>
#include <poll.h>
#include <unistd.h>

#include <boost/asio/io_context.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <nlohmann/json.hpp>

#include "server/app/gateway.hpp"
#include "server/app/gateway.hpp"
#include "server/gateway/json_api_installer.hpp"
#include "server/gateway/json_rest.hpp"
#include "server/gateway/binary_push.hpp"
#include "server/gateway/json_socket.hpp"
#include "test/support/skip.hpp"

extern char** environ;

namespace rr::server::gateway::testing {

using json = nlohmann::json;
using namespace std::chrono_literals;
namespace beast = boost::beast;
namespace bhttp = boost::beast::http;
namespace websocket = boost::beast::websocket;
using tcp = boost::asio::ip::tcp;

/// rr_interop_service's path: RR_INTEROP_SERVICE_REL is relative to this test executable's folder, so
/// the compile flags are the same in every build folder (ccache hits across build/<name>).
inline const char* interop_service_bin() {
#ifdef RR_INTEROP_SERVICE_REL
    static const std::string path = [] {
        std::error_code ec;
        auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
        return ec ? std::string() : (exe.parent_path() / RR_INTEROP_SERVICE_REL).lexically_normal().string();
    }();
    return path.empty() ? nullptr : path.c_str();
#else
    return nullptr;
#endif
}

/// rr_interop_service as a child process on an ephemeral port; SIGTERM when destroyed.
class InteropProcess {
public:
    InteropProcess() {
        int fds[2];
        REQUIRE(::pipe(fds) == 0);
        posix_spawn_file_actions_t actions;
        posix_spawn_file_actions_init(&actions);
        posix_spawn_file_actions_adddup2(&actions, fds[1], STDOUT_FILENO);
        posix_spawn_file_actions_addclose(&actions, fds[0]);
        std::string bin = interop_service_bin();
        std::vector<std::string> args = {bin, "--port", "0", "--max-lifetime", "300"};
        std::vector<char*> argv;
        for (auto& a : args) argv.push_back(a.data());
        argv.push_back(nullptr);
        const int rc = posix_spawn(&pid_, bin.c_str(), &actions, nullptr, argv.data(), environ);
        posix_spawn_file_actions_destroy(&actions);
        ::close(fds[1]);
        REQUIRE(rc == 0);
        // The ready line: {"url": "rr+tcp://127.0.0.1:PORT/?service=interop", "port": PORT, …}
        std::string line;
        const auto until = std::chrono::steady_clock::now() + 60s;
        while (line.find('\n') == std::string::npos && std::chrono::steady_clock::now() < until) {
            pollfd p{fds[0], POLLIN, 0};
            if (::poll(&p, 1, 200) <= 0) continue;
            char buf[512];
            const auto n = ::read(fds[0], buf, sizeof buf);
            if (n <= 0) break;
            line.append(buf, static_cast<std::size_t>(n));
        }
        ::close(fds[0]);
        auto j = json::parse(line.substr(0, line.find('\n')), nullptr, false);
        REQUIRE(j.is_object());
        url_ = j["url"].get<std::string>();
        port_ = j["port"].get<std::uint16_t>();
    }
    ~InteropProcess() { stop(); }

    void stop() {
        if (pid_ <= 0) return;
        ::kill(pid_, SIGTERM);
        int status = 0;
        for (int i = 0; i < 200; ++i) {
            if (::waitpid(pid_, &status, WNOHANG) == pid_) {
                pid_ = -1;
                return;
            }
            std::this_thread::sleep_for(25ms);
        }
        ::kill(pid_, SIGKILL);
        ::waitpid(pid_, &status, 0);
        pid_ = -1;
    }

    const std::string& url() const { return url_; }
    std::uint16_t port() const { return port_; }

private:
    pid_t pid_ = -1;
    std::string url_;
    std::uint16_t port_ = 0;
};

/// A Gateway (demo off) with device "interop" at `url`, the JSON API installed; waits until connected.
class TestGateway {
public:
    /// `configure` (optional) changes the configuration before the gateway starts (e.g. recordings.root).
    explicit TestGateway(const std::string& url, bool wait = true, JsonSocketOptions ws_options = {},
                         const std::function<void(app::GatewayConfig&)>& configure = {}) {
        app::GatewayConfig cfg;
        cfg.local = false;  // tests run side by side: no shared NodeName on this computer
        cfg.port = 0;
        cfg.listen = "127.0.0.1";
        cfg.demo = false;
        cfg.threads = 2;
        cfg.allowed_origins = {"http://allowed.test"};
        DeviceConfig d;
        d.name = "interop";
        d.url = url;
        d.backoff_initial = 100ms;
        d.backoff_max = 200ms;
        cfg.devices.push_back(d);
        if (configure) configure(cfg);
        auto installer = [this, ws_options](http::HttpServer& http, const std::vector<std::shared_ptr<DeviceMirror>>& devices,
                                                   std::shared_ptr<auth::GatewayAuth>) {
            api_ = std::make_shared<JsonApi>(devices);
            install_json_rest(http, api_);
            sockets_ = install_json_socket(http, api_, ws_options);
            return api_;
        };
        auto g = app::Gateway::start(cfg, {}, installer);
        REQUIRE(g);
        gateway_ = std::move(*g);
        if (wait) REQUIRE(wait_state(DeviceState::connected));
    }
    ~TestGateway() {
        // Our references go first: the sessions' timers must go with the HttpServer, before the node.
        sockets_.reset();
        api_.reset();
        if (gateway_) gateway_->stop();
        gateway_.reset();
    }

    bool wait_state(DeviceState s, std::chrono::milliseconds timeout = 30000ms) {
        const auto until = std::chrono::steady_clock::now() + timeout;
        while (std::chrono::steady_clock::now() < until) {
            if (gateway_->devices().front()->status().state == s) return true;
            std::this_thread::sleep_for(10ms);
        }
        return false;
    }

    std::uint16_t port() const { return gateway_->port(); }
    app::Gateway& gateway() { return *gateway_; }
    const std::shared_ptr<JsonApi>& api() const { return api_; }
    JsonSocketServer& sockets() { return *sockets_; }

private:
    std::shared_ptr<JsonApi> api_;
    std::shared_ptr<JsonSocketServer> sockets_;
    std::unique_ptr<app::Gateway> gateway_;
};

struct HttpReply {
    unsigned status = 0;
    json body;
    bhttp::response<bhttp::string_body> raw;
};

inline HttpReply http_request(std::uint16_t port, bhttp::verb method, const std::string& target,
                              const std::string& body = {}, const std::string& origin = {}) {
    boost::asio::io_context io;
    beast::tcp_stream s(io);
    s.connect(tcp::endpoint(boost::asio::ip::make_address("127.0.0.1"), port));
    bhttp::request<bhttp::string_body> req{method, target, 11};
    req.set(bhttp::field::host, "localhost");
    if (!origin.empty()) req.set(bhttp::field::origin, origin);
    if (!body.empty()) {
        req.set(bhttp::field::content_type, "application/json");
        req.body() = body;
    }
    req.prepare_payload();
    beast::error_code ec;
    bhttp::write(s, req, ec);  // a server refusing a large body may close before reading it all
    beast::flat_buffer b;
    HttpReply r;
    bhttp::response_parser<bhttp::string_body> parser;
    parser.body_limit(64u << 20);
    bhttp::read(s, b, parser, ec);
    if (ec) return r;  // status 0
    r.raw = parser.release();
    r.status = r.raw.result_int();
    r.body = json::parse(r.raw.body(), nullptr, false);
    return r;
}

inline HttpReply http_get(std::uint16_t port, const std::string& target) {
    return http_request(port, bhttp::verb::get, target);
}
inline HttpReply http_put(std::uint16_t port, const std::string& target, const json& body) {
    return http_request(port, bhttp::verb::put, target, body.dump());
}
inline HttpReply http_post(std::uint16_t port, const std::string& target, const json& body) {
    return http_request(port, bhttp::verb::post, target, body.dump());
}

/// A JSON WebSocket client on its own thread: messages read into a queue (unless `read` is false,
/// for a client that never reads), writes posted to the client's thread.
class WsClient {
public:
    explicit WsClient(std::uint16_t port, bool read = true, std::string protocol = std::string(kJsonSubprotocol),
                      std::optional<int> receive_buffer = std::nullopt)
        : ws_(io_) {
        auto& sock = beast::get_lowest_layer(ws_).socket();
        sock.open(tcp::v4());
        if (receive_buffer) sock.set_option(boost::asio::socket_base::receive_buffer_size(*receive_buffer));
        beast::get_lowest_layer(ws_).connect(tcp::endpoint(boost::asio::ip::make_address("127.0.0.1"), port));
        ws_.set_option(websocket::stream_base::decorator(
            [protocol](websocket::request_type& req) { req.set(bhttp::field::sec_websocket_protocol, protocol); }));
        ws_.handshake(handshake_, "localhost", "/");
        ws_.text(true);
        if (read) start_read();
        guard_.emplace(io_.get_executor());
        thread_ = std::thread([this] { io_.run(); });
    }
    ~WsClient() { close(); }

    const websocket::response_type& handshake_response() const { return handshake_; }

    void close() {
        if (!thread_.joinable()) return;
        // Pending reads and writes end with an error once the socket is closed; then run() returns.
        boost::asio::post(io_, [this] {
            beast::error_code ec;
            beast::get_lowest_layer(ws_).socket().shutdown(tcp::socket::shutdown_both, ec);
            beast::get_lowest_layer(ws_).socket().close(ec);
            guard_.reset();
        });
        thread_.join();
    }

    /// Stops reading after the read in progress (a client that stops reading for good).
    void pause_reading() {
        boost::asio::post(io_, [this] { paused_ = true; });
    }

    void send(const json& j) { send_text(j.dump()); }
    void send_text(std::string text) {
        boost::asio::post(io_, [this, text = std::move(text)]() mutable {
            writes_.push_back(std::move(text));
            if (writes_.size() == 1) write_next();
        });
    }

    /// The next message (reply or push), or nullopt after `timeout`.
    std::optional<json> next(std::chrono::milliseconds timeout = 30000ms) {  // defaults: bounds on a hang
        std::unique_lock lock(mutex_);
        if (!cv_.wait_for(lock, timeout, [&] { return !inbox_.empty() || read_failed_; })) return std::nullopt;
        if (inbox_.empty()) return std::nullopt;
        auto j = std::move(inbox_.front());
        inbox_.pop_front();
        return j;
    }

    /// Sends a request with a fresh id and waits for its reply; pushes meanwhile go to pushes().
    json request(json msg, std::chrono::milliseconds timeout = 30000ms) {
        const int id = ++next_id_;
        msg["id"] = id;
        send(msg);
        const auto until = std::chrono::steady_clock::now() + timeout;
        while (std::chrono::steady_clock::now() < until) {
            auto m = next(std::chrono::duration_cast<std::chrono::milliseconds>(until - std::chrono::steady_clock::now()));
            if (!m) break;
            if (m->contains("id") && (*m)["id"] == id) return *m;
            pushes_.push_back(std::move(*m));
        }
        FAIL("no reply to " << msg.dump());
        return {};
    }

    /// Waits for a push matching `pred` (looking at the pushes already kept first).
    std::optional<json> wait_push(const std::function<bool(const json&)>& pred, std::chrono::milliseconds timeout = 30000ms) {
        for (auto it = pushes_.begin(); it != pushes_.end(); ++it) {
            if (pred(*it)) {
                json j = *it;
                pushes_.erase(it);
                return j;
            }
        }
        const auto until = std::chrono::steady_clock::now() + timeout;
        while (std::chrono::steady_clock::now() < until) {
            auto m = next(std::chrono::duration_cast<std::chrono::milliseconds>(until - std::chrono::steady_clock::now()));
            if (!m) break;
            if (pred(*m)) return m;
            pushes_.push_back(std::move(*m));
        }
        return std::nullopt;
    }

    std::deque<json>& pushes() { return pushes_; }

private:
    void start_read() {
        ws_.async_read(buffer_, [this](beast::error_code ec, std::size_t) {
            std::lock_guard lock(mutex_);
            if (ec) {
                read_failed_ = true;
                cv_.notify_all();
                return;
            }
            if (ws_.got_binary()) {
                // A binary push: kept as the JSON it decodes to, marked so tests can tell.
                auto j = decode_binary_push(beast::buffers_to_string(buffer_.data()));
                inbox_.push_back(j ? *j : json{{"$bad_binary", j.error().message}});
                inbox_.back()["$binary_message"] = true;
            } else {
                inbox_.push_back(json::parse(beast::buffers_to_string(buffer_.data()), nullptr, false));
            }
            buffer_.consume(buffer_.size());
            cv_.notify_all();
            if (!paused_) start_read();
        });
    }
    void write_next() {
        ws_.async_write(boost::asio::buffer(writes_.front()), [this](beast::error_code ec, std::size_t) {
            writes_.pop_front();
            if (!ec && !writes_.empty()) write_next();
        });
    }

    boost::asio::io_context io_;
    websocket::stream<beast::tcp_stream> ws_;
    websocket::response_type handshake_;
    beast::flat_buffer buffer_;
    std::deque<std::string> writes_;
    std::optional<boost::asio::executor_work_guard<boost::asio::io_context::executor_type>> guard_;
    std::thread thread_;
    std::mutex mutex_;
    std::condition_variable cv_;
    std::deque<json> inbox_;
    bool read_failed_ = false;
    bool paused_ = false;  // touched on the client's thread only
    std::deque<json> pushes_;
    int next_id_ = 0;
};

}  // namespace rr::server::gateway::testing

/// Ends the test case as skipped (test/support/skip.hpp: ctest shows Skipped) when rr_interop_service is
/// not part of the build. When it is (test/interop makes rr_server_tests depend on it), a missing or
/// broken program fails the test instead. Call first, before any assertion.
#define RR_SKIP_WITHOUT_INTEROP_SERVICE()                                                                  \
    do {                                                                                                  \
        if (!::rr::server::gateway::testing::interop_service_bin())                                       \
            RR_SKIP("rr_interop_service is not part of this build (test/interop): JSON API test not run"); \
    } while (false)
