// HttpServer on the node's port: routes, static files, Origin policy, and RR over WebSocket.
#include <catch2/catch.hpp>

#include <array>
#include <atomic>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <thread>

#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>

#include "core/session/client_session.hpp"
#include "core/session/elements.hpp"
#include "server/http/http_server.hpp"
#include "server/node/node.hpp"
#include "server/transport/tcp_listener.hpp"
#include "test/support/eventually.hpp"

using namespace rr;
using namespace rr::server;
using namespace std::chrono_literals;
namespace beast = boost::beast;
namespace bhttp = boost::beast::http;
namespace websocket = boost::beast::websocket;
using tcp = boost::asio::ip::tcp;

namespace {

constexpr const char* kDef = "service example.wstest\n\nstdver 0.10\n\nobject Obj\n    property double x\nend\n";

class TinyService : public Service {
public:
    const std::string& name() const override { return name_; }
    std::vector<std::string> service_definitions() const override { return {kDef}; }
    std::optional<std::string> service_definition(std::string_view) const override { return std::string(kDef); }
    ObjectTypeInfo root_type() const override { return {"example.wstest.Obj", {}}; }
    void object_type(const SessionRef&, const std::string&, std::function<void(Result<ObjectTypeInfo>)> done) override {
        done(root_type());
    }
    void handle_entry(const SessionRef&, MessageEntry&& e, Responder r) override {
        MessageEntry m;
        m.elements.push_back(make_scalar_element("value", 3.25));
        r.respond(std::move(m));
    }

private:
    std::string name_ = "ws";
};

struct Fixture {
    std::shared_ptr<Node> node = Node::create(NodeOptions{NodeID(), "ws.node", 2, {}, 0, 5000ms});
    std::shared_ptr<http::HttpServer> server;
    std::filesystem::path root = std::filesystem::temp_directory_path() / ("rr_http_test_" + std::to_string(::getpid()));
    std::uint16_t port = 0;

    /// Lines of HttpOptions::on_websocket.
    std::shared_ptr<std::vector<std::string>> ws_log = std::make_shared<std::vector<std::string>>();
    std::shared_ptr<std::mutex> ws_log_mutex = std::make_shared<std::mutex>();

    /// The last socket of "test.push.burst.v1", set on the socket's strand once its burst is sent (read by
    /// the test: under TSan and a loaded CPU the burst outlasted a fixed wait).
    struct SocketSlot {
        std::mutex mutex;
        std::shared_ptr<http::JsonSocket> socket;
        void set(std::shared_ptr<http::JsonSocket> s) {
            std::lock_guard lock(mutex);
            socket = std::move(s);
        }
        std::shared_ptr<http::JsonSocket> get() {
            std::lock_guard lock(mutex);
            return socket;
        }
    };
    std::shared_ptr<SocketSlot> burst_socket = std::make_shared<SocketSlot>();

    explicit Fixture(std::vector<std::string> trusted_proxies = {},
                     std::size_t queue_limit = http::HttpOptions{}.json_socket_queue_limit,
                     bool gathered_writes = http::HttpOptions{}.websocket_gathered_writes) {
        std::filesystem::create_directories(root / "sub");
        std::ofstream(root / "index.html") << "<h1>dash</h1>";
        std::ofstream(root / "sub" / "app.wasm") << "wasm";
        http::HttpOptions opts;
        opts.allowed_origins = {"http://localhost:8080", "http://*.example.org"};
        opts.static_root = root.string();
        opts.json_socket_queue_limit = queue_limit;
        opts.websocket_gathered_writes = gathered_writes;
        for (const auto& p : trusted_proxies) opts.trusted_proxies.push_back(*http::parse_ip_network(p));
        opts.on_websocket = [log = ws_log, m = ws_log_mutex](const std::string& line) {
            std::lock_guard lock(*m);
            log->push_back(line);
        };
        server = std::make_shared<http::HttpServer>(node, opts);
        server->add_route(bhttp::verb::get, "/livez", [](const http::Request& req, http::Responder respond) {
            respond(http::make_response(req, bhttp::status::ok, "ok\n"));
        });
        server->add_subprotocol("test.echo.v1", http::JsonSocketHandler{
                                                    {},
                                                    [](const std::shared_ptr<http::JsonSocket>& s, std::string text) {
                                                        s->send("echo:" + text);
                                                    },
                                                    {}});
        // "flood": 200 pushes of 64 KiB, then one urgent reply.
        server->add_subprotocol("test.flood.v1", http::JsonSocketHandler{
                                                     {},
                                                     [](const std::shared_ptr<http::JsonSocket>& s, std::string) {
                                                         for (int i = 0; i < 200; ++i)
                                                             s->send("push " + std::to_string(i) + std::string(64 * 1024, ' '));
                                                         s->send_urgent("reply");
                                                     },
                                                     {}});
        // "shared": a message, then pushes whose bodies are shared (a short head, a long one, an offset
        // past the body's end), then one urgent reply.
        server->add_subprotocol("test.push.shared.v1", http::JsonSocketHandler{
                                                      {},
                                                      [](const std::shared_ptr<http::JsonSocket>& s, std::string) {
                                                          auto body = std::make_shared<const std::string>("{\"b\":2}");
                                                          s->send("first");
                                                          s->send_shared("{\"a\":1,", body, 1);
                                                          s->send_shared(std::string(200, 'h'), body, 0);
                                                          s->send_shared("only", body, 999);
                                                          s->send_urgent("reply");
                                                      },
                                                      {}});
        // "threads": 4 threads send 200 shared pushes each ("<thread>:<n>,…"), at once (800 are below
        // the queue limit, though none is taken before the handler returns: it runs on the strand).
        server->add_subprotocol("test.push.threads.v1", http::JsonSocketHandler{
                                                       {},
                                                       [](const std::shared_ptr<http::JsonSocket>& s, std::string) {
                                                           auto body = std::make_shared<const std::string>(",shared");
                                                           std::vector<std::thread> senders;
                                                           for (int t = 0; t < 4; ++t)
                                                               senders.emplace_back([s, body, t] {
                                                                   for (int n = 0; n < 200; ++n)
                                                                       s->send_shared(std::to_string(t) + ":" + std::to_string(n), body, 0);
                                                               });
                                                           for (auto& t : senders) t.join();
                                                       },
                                                       {}});
        // "burst": 100 messages of 64 KiB at once ("burst <n> …"), with the socket kept for the test.
        server->add_subprotocol("test.push.burst.v1", http::JsonSocketHandler{
                                                     {},
                                                     [kept = burst_socket](const std::shared_ptr<http::JsonSocket>& s, std::string) {
                                                         for (int i = 0; i < 100; ++i)
                                                             s->send("burst " + std::to_string(i) + std::string(64 * 1024, ' '));
                                                         kept->set(s);  // after the burst: its drops are all counted
                                                     },
                                                     {}});
        REQUIRE(node->register_service(std::make_shared<TinyService>()));
        TcpListenerOptions tcp;
        tcp.http = http_handler(server);
        port = *listen_tcp(node, "127.0.0.1", 0, std::move(tcp));
    }
    ~Fixture() {
        node->shutdown();
        std::error_code ec;
        std::filesystem::remove_all(root, ec);
    }

    std::vector<std::string> websocket_log() const {
        std::lock_guard lock(*ws_log_mutex);
        return *ws_log;
    }

    bhttp::response<bhttp::string_body> get(std::string target, std::string origin = {},
                                            std::vector<std::pair<std::string, std::string>> headers = {}) {
        boost::asio::io_context io;
        beast::tcp_stream s(io);
        s.connect(tcp::endpoint(boost::asio::ip::make_address("127.0.0.1"), port));
        bhttp::request<bhttp::string_body> req{bhttp::verb::get, target, 11};
        req.set(bhttp::field::host, "localhost");
        if (!origin.empty()) req.set(bhttp::field::origin, origin);
        for (const auto& [name, value] : headers) req.set(name, value);
        bhttp::write(s, req);
        beast::flat_buffer b;
        bhttp::response<bhttp::string_body> res;
        bhttp::read(s, b, res);
        return res;
    }
};

}  // namespace

TEST_CASE("HTTP routes and static files share the RR port") {
    Fixture f;
    auto live = f.get("/livez");
    CHECK(live.result() == bhttp::status::ok);
    CHECK(live.body() == "ok\n");
    auto index = f.get("/");
    CHECK(index.result() == bhttp::status::ok);
    CHECK(index.body() == "<h1>dash</h1>");
    CHECK(index[bhttp::field::content_type] == "text/html; charset=utf-8");
    auto wasm = f.get("/sub/app.wasm");
    CHECK(wasm[bhttp::field::content_type] == "application/wasm");
    CHECK(f.get("/nothing").result() == bhttp::status::not_found);
    CHECK(f.get("/../etc/passwd").result() == bhttp::status::bad_request);
}

TEST_CASE("Origins outside the allowlist get 403") {
    Fixture f;
    CHECK(f.get("/livez", "http://localhost:8080").result() == bhttp::status::ok);
    CHECK(f.get("/livez", "http://a.example.org").result() == bhttp::status::ok);
    CHECK(f.get("/livez", "http://evil.test").result() == bhttp::status::forbidden);
    CHECK(f.get("/livez", "http://example.org.evil.test").result() == bhttp::status::forbidden);
}

TEST_CASE("origin matching follows the allowlist forms") {
    using http::origin_allowed;
    std::vector<std::string> list{"null", "file://", "https://*.robotraconteur.com", "http://localhost:8080"};
    CHECK(origin_allowed(list, "null"));
    CHECK(origin_allowed(list, "file:///tmp/x.html"));
    CHECK(origin_allowed(list, "https://www.robotraconteur.com"));
    CHECK_FALSE(origin_allowed(list, "https://robotraconteur.com.evil"));
    CHECK_FALSE(origin_allowed(list, "http://localhost:8081"));
    CHECK(origin_allowed({"*"}, "http://anything"));
    CHECK(http::same_origin("http://127.0.0.1:8080", "127.0.0.1:8080"));
    CHECK(http::same_origin("https://gw.example.org", "GW.example.org"));
    CHECK_FALSE(http::same_origin("http://evil.test", "127.0.0.1:8080"));
    CHECK_FALSE(http::same_origin("http://127.0.0.1:8080", ""));
    CHECK_FALSE(http::same_origin("http://127.0.0.1:80801", "127.0.0.1:8080"));
}

namespace {

// A client WebSocket to the fixture's port asking for `subprotocol`; the handshake's response in `res`.
void open_text_socket(websocket::stream<beast::tcp_stream>& ws, std::uint16_t port, const char* subprotocol,
                      websocket::response_type& res) {
    beast::get_lowest_layer(ws).connect(tcp::endpoint(boost::asio::ip::make_address("127.0.0.1"), port));
    ws.set_option(websocket::stream_base::decorator(
        [subprotocol](websocket::request_type& req) { req.set(bhttp::field::sec_websocket_protocol, subprotocol); }));
    ws.handshake(res, "localhost", "/");
    ws.text(true);
}

/// A client of one of the fixture's JSON subprotocols that has sent its first message.
struct SubprotocolClient {
    boost::asio::io_context io;
    websocket::stream<beast::tcp_stream> ws{io};

    SubprotocolClient(std::uint16_t port, const char* subprotocol, const std::string& first) {
        websocket::response_type res;
        open_text_socket(ws, port, subprotocol, res);
        ws.write(boost::asio::buffer(first));
    }
    /// The next message's text.
    std::string read() {
        beast::flat_buffer b;
        ws.read(b);
        return beast::buffers_to_string(b.data());
    }
};

}  // namespace

TEST_CASE("a JSON subprotocol WebSocket is served by its handler") {
    Fixture f;
    boost::asio::io_context io;
    websocket::stream<beast::tcp_stream> ws(io);
    websocket::response_type res;
    open_text_socket(ws, f.port, "test.echo.v1", res);
    CHECK(res[bhttp::field::sec_websocket_protocol] == "test.echo.v1");
    ws.write(boost::asio::buffer(std::string("hi")));
    beast::flat_buffer b;
    ws.read(b);
    CHECK(beast::buffers_to_string(b.data()) == "echo:hi");
}

namespace {

// The on_websocket line of one JSON WebSocket opened with `headers`.
std::string websocket_line(Fixture& f, std::vector<std::pair<std::string, std::string>> headers) {
    boost::asio::io_context io;
    websocket::stream<beast::tcp_stream> ws(io);
    beast::get_lowest_layer(ws).connect(tcp::endpoint(boost::asio::ip::make_address("127.0.0.1"), f.port));
    ws.set_option(websocket::stream_base::decorator([headers](websocket::request_type& req) {
        req.set(bhttp::field::sec_websocket_protocol, "test.echo.v1");
        for (const auto& [name, value] : headers) req.set(name, value);
    }));
    const auto before = f.websocket_log().size();
    ws.handshake("localhost", "/");  // the line is written before the handshake's answer
    auto log = f.websocket_log();
    ws.close(websocket::close_code::normal);
    return log.size() == before + 1 ? log.back() : std::string("(no line)");
}

}  // namespace

TEST_CASE("X-Forwarded-For/-Proto are believed from a trusted proxy only") {
    const std::vector<std::pair<std::string, std::string>> forged{{"X-Forwarded-For", "198.51.100.7"},
                                                                  {"X-Forwarded-Proto", "https"}};
    SECTION("no trusted proxy: the headers change nothing") {
        Fixture f;
        auto line = websocket_line(f, forged);
        CHECK_THAT(line, Catch::StartsWith("WebSocket test.echo.v1 from 127.0.0.1:"));
        CHECK_THAT(line, !Catch::Contains("198.51.100.7"));
        // same-origin accepts either scheme for the Host
        CHECK(f.get("/livez", "http://localhost", forged).result() == bhttp::status::ok);
        CHECK(f.get("/livez", "https://localhost", forged).result() == bhttp::status::ok);
    }
    SECTION("the peer is a trusted proxy: the client and its scheme come from the headers") {
        Fixture f({"127.0.0.0/8"});
        auto line = websocket_line(f, forged);
        CHECK_THAT(line, Catch::StartsWith("WebSocket test.echo.v1 from 198.51.100.7 (https, via 127.0.0.1:"));
        // the page was https: an http Origin for the same Host is another origin (and not in the allowlist)
        CHECK(f.get("/livez", "https://localhost", forged).result() == bhttp::status::ok);
        CHECK(f.get("/livez", "http://localhost", forged).result() == bhttp::status::forbidden);
        // without X-Forwarded-Proto the scheme is unknown: either is same-origin
        CHECK(f.get("/livez", "http://localhost", {{"X-Forwarded-For", "198.51.100.7"}}).result() == bhttp::status::ok);
        CHECK_THAT(websocket_line(f, {}), Catch::StartsWith("WebSocket test.echo.v1 from 127.0.0.1:"));
    }
}

TEST_CASE("a JSON WebSocket's urgent message goes ahead of the pushes still waiting") {
    Fixture f;
    SubprotocolClient client(f.port, "test.flood.v1", "flood");
    // The handler queues the 200 pushes (13 MB) and the reply in one run on the socket's strand, so the
    // reply meets the backlog whenever this client starts reading.
    int reply_at = -1, pushes = 0, last_push = -1;
    bool in_order = true;
    for (int i = 0; i < 201; ++i) {
        const std::string text = client.read();
        if (text == "reply") {
            reply_at = i;
            continue;
        }
        REQUIRE(text.rfind("push ", 0) == 0);
        const int n = std::stoi(text.substr(5));
        in_order = in_order && n == last_push + 1;
        last_push = n;
        ++pushes;
    }
    CHECK(pushes == 200);  // nothing dropped: below the queue limit
    CHECK(in_order);
    // Only what was already written (socket buffers) comes first; without priority it would be last.
    REQUIRE(reply_at >= 0);
    CHECK(reply_at < 100);
}

TEST_CASE("a JSON WebSocket writes a shared body after each message's own head, in order with the rest") {
    Fixture f;
    SubprotocolClient client(f.port, "test.push.shared.v1", "go");
    std::vector<std::string> got;
    for (int i = 0; i < 5; ++i) {
        got.push_back(client.read());
        CHECK(client.ws.got_text());
    }
    // The handler runs on the socket's strand, so all five reach the queue in one batch, before any
    // write: the urgent reply goes ahead of the rest, which keep their order.
    const std::vector<std::string> expected{"reply", "first", R"({"a":1,"b":2})", std::string(200, 'h') + R"({"b":2})",
                                            "only"};
    CHECK(got == expected);
}

TEST_CASE("a JSON WebSocket keeps each sending thread's order and loses nothing below its limit") {
    Fixture f;
    SubprotocolClient client(f.port, "test.push.threads.v1", "go");
    beast::get_lowest_layer(client.ws).expires_after(60s);  // a lost message fails the read, not the suite (a bound on a hang)
    std::array<int, 4> next{};
    bool in_order = true;
    for (int i = 0; i < 4 * 200; ++i) {
        const std::string text = client.read();
        const auto colon = text.find(':'), comma = text.find(',');
        REQUIRE(colon == 1);
        REQUIRE(text.substr(comma) == ",shared");
        const int t = text[0] - '0';
        REQUIRE((t >= 0 && t < 4));
        in_order = in_order && std::stoi(text.substr(2, comma - 2)) == next[t];
        ++next[t];
    }
    CHECK(in_order);
    CHECK(next == std::array<int, 4>{200, 200, 200, 200});
}

TEST_CASE("a JSON WebSocket's burst beyond its queue limit drops the oldest and counts them") {
    Fixture f({}, 16);
    SubprotocolClient client(f.port, "test.push.burst.v1", "go");
    std::shared_ptr<http::JsonSocket> socket;
    // Set once the whole burst is sent (queued or dropped) while this client does not read yet.
    REQUIRE(rr::testing::eventually([&] { return (socket = f.burst_socket->get()) != nullptr; }));
    CHECK(socket->queued() <= 2 * 16);
    CHECK(socket->queued_bytes() <= 2 * 16 * (64 * 1024 + 16));
    const auto dropped = socket->dropped();
    CHECK(dropped >= 100 - 2 * 16);
    // What is left arrives in order and ends with the newest.
    beast::get_lowest_layer(client.ws).expires_after(60s);  // a lost message fails the read, not the suite (a bound on a hang)
    int last = -1, received = 0;
    bool in_order = true;
    while (last < 99) {
        const std::string text = client.read();
        REQUIRE(text.rfind("burst ", 0) == 0);
        const int n = std::stoi(text.substr(6));
        in_order = in_order && n > last;
        last = n;
        ++received;
    }
    CHECK(in_order);
    CHECK(received + dropped == 100u);
    CHECK(socket->dropped() == dropped);
    CHECK(socket->queued() == 0);
    CHECK(socket->queued_bytes() == 0);
}

TEST_CASE("a stopping server ends a JSON WebSocket that is reading and writing at once, within the bound") {
    // close_going_away meets a session with a read pending (always) and a write pending (a client that
    // does not read a flood): the close handshake's bound must not touch the stream's expiry, which Beast
    // refuses with both pending (an assertion: the process aborted in a CI run of issue 57's stop).
    Fixture f({}, 1000);
    auto kept = std::make_shared<Fixture::SocketSlot>();
    auto closed = std::make_shared<std::atomic<bool>>(false);
    f.server->add_subprotocol("test.flood.kept.v1",
                              http::JsonSocketHandler{{},
                                                      [kept](const std::shared_ptr<http::JsonSocket>& s, std::string) {
                                                          for (int i = 0; i < 400; ++i) s->send(std::string(64 * 1024, 'f'));
                                                          kept->set(s);
                                                      },
                                                      [closed](const std::shared_ptr<http::JsonSocket>&) { *closed = true; }});
    SubprotocolClient client(f.port, "test.flood.kept.v1", "go");  // never reads
    std::shared_ptr<http::JsonSocket> socket;
    REQUIRE(rr::testing::eventually([&] { return (socket = kept->get()) != nullptr; }));
    // The kernel's buffers are full (25 MiB queued against a few): a write stays pending.
    REQUIRE(rr::testing::eventually([&] {
        const auto before = socket->queued();
        std::this_thread::sleep_for(50ms);
        return before > 0 && socket->queued() == before;
    }));
    f.server->go_away();
    CHECK(rr::testing::eventually([&] { return closed->load(); }));  // after the 1 s bound: the client never answers
}

namespace {

/// Registers "test.push.many.v1": on a message, `count` small pushes ("m<n>") at once (the handler
/// runs on the socket's strand: they reach its queue together), then close() when `close_after`;
/// the socket is kept in `kept` after the pushes.
void add_many_pushes(Fixture& f, int count, bool close_after, std::shared_ptr<Fixture::SocketSlot> kept) {
    f.server->add_subprotocol("test.push.many.v1",
                              http::JsonSocketHandler{{},
                                                      [count, close_after, kept](const std::shared_ptr<http::JsonSocket>& s, std::string) {
                                                          for (int i = 0; i < count; ++i) s->send("m" + std::to_string(i));
                                                          if (close_after) s->close();
                                                          kept->set(s);
                                                      },
                                                      {}});
}

/// Reads `count` pushes of add_many_pushes in order; false at the first one out of order.
bool read_many_in_order(SubprotocolClient& client, int count) {
    for (int i = 0; i < count; ++i)
        if (client.read() != "m" + std::to_string(i)) return false;
    return true;
}

}  // namespace

TEST_CASE("a JSON WebSocket's pushes waiting together leave in fewer writes than messages, Beast's frames in order") {
    for (bool gathered : {true, false}) {
        INFO("websocket_gathered_writes " << gathered);
        Fixture f({}, 1024, gathered);
        auto kept = std::make_shared<Fixture::SocketSlot>();
        add_many_pushes(f, 500, false, kept);
        SubprotocolClient client(f.port, "test.push.many.v1", "go");
        beast::get_lowest_layer(client.ws).expires_after(60s);  // a bound on a hang
        CHECK(read_many_in_order(client, 500));
        std::shared_ptr<http::JsonSocket> socket;
        REQUIRE(rr::testing::eventually([&] { return (socket = kept->get()) != nullptr; }));
        // The handshake's response, then the pushes: gathered, ~4 KiB of frames in a write or two (one
        // batch, or two when the strand took the first pushes before the rest arrived); without the
        // gathering, one write each.
        if (gathered)
            CHECK(socket->writes() < 10);
        else
            CHECK(socket->writes() >= 500);
        CHECK(rr::testing::eventually([&] { return socket->queued() == 0 && socket->queued_bytes() == 0; }));
    }
}

TEST_CASE("a JSON WebSocket closed right after a batch of pushes sends the batch, then the close frame") {
    Fixture f;
    auto kept = std::make_shared<Fixture::SocketSlot>();
    add_many_pushes(f, 300, true, kept);
    SubprotocolClient client(f.port, "test.push.many.v1", "go");
    beast::get_lowest_layer(client.ws).expires_after(60s);  // a bound on a hang
    CHECK(read_many_in_order(client, 300));
    beast::flat_buffer b;
    beast::error_code ec;
    client.ws.read(b, ec);
    CHECK(ec == websocket::error::closed);
    CHECK(client.ws.reason().code == websocket::close_code::normal);
}

TEST_CASE("an unknown subprotocol is refused with 426") {
    Fixture f;
    boost::asio::io_context io;
    websocket::stream<beast::tcp_stream> ws(io);
    beast::get_lowest_layer(ws).connect(tcp::endpoint(boost::asio::ip::make_address("127.0.0.1"), f.port));
    ws.set_option(websocket::stream_base::decorator(
        [](websocket::request_type& req) { req.set(bhttp::field::sec_websocket_protocol, "nope"); }));
    websocket::response_type res;
    beast::error_code ec;
    ws.handshake(res, "localhost", "/", ec);
    CHECK(ec);
    CHECK(res.result() == bhttp::status::upgrade_required);
    // The answer says what this server speaks.
    CHECK_THAT(res.body(), Catch::Contains("test.echo.v1") && Catch::Contains("robotraconteur.robotraconteur.com"));
}

TEST_CASE("a WebSocket without subprotocol whose first message is text gets a JSON error, then a close") {
    // A JSON API client that forgot `Sec-WebSocket-Protocol`: before, the node read its text as RR
    // and dropped it silently (issue 15).
    Fixture f;
    boost::asio::io_context io;
    websocket::stream<beast::tcp_stream> ws(io);
    beast::get_lowest_layer(ws).connect(tcp::endpoint(boost::asio::ip::make_address("127.0.0.1"), f.port));
    websocket::response_type res;
    ws.handshake(res, "localhost", "/");
    CHECK(res[bhttp::field::sec_websocket_protocol].empty());
    ws.text(true);
    ws.write(boost::asio::buffer(std::string(R"({"id": 1, "op": "devices"})")));
    beast::flat_buffer b;
    ws.read(b);
    CHECK(ws.got_text());
    const std::string text = beast::buffers_to_string(b.data());
    CHECK_THAT(text, Catch::StartsWith(R"({"error": {"name": "RobotRaconteur.ProtocolError", "message": ")"));
    CHECK_THAT(text, Catch::Contains("open the WebSocket with the subprotocol test.echo.v1, test.flood.v1"));
    beast::error_code ec;
    b.clear();
    ws.read(b, ec);
    CHECK(ec == websocket::error::closed);
    CHECK(ws.reason().code == websocket::close_code::policy_error);
    CHECK_THAT(std::string(ws.reason().reason.c_str()), Catch::Contains("subprotocol test.echo.v1"));
}

TEST_CASE("a route for any method sees every method the port serves, a method it does not serve is dropped") {
    Fixture f;
    f.server->add_route_any_method("/any", [](const http::Request& req, http::Responder respond) {
        respond(http::make_response(req, bhttp::status::ok, std::string(req.method_string())));
    });
    // A route of the method wins over the any-method route, whichever was added first.
    f.server->add_route(bhttp::verb::put, "/any", [](const http::Request& req, http::Responder respond) {
        respond(http::make_response(req, bhttp::status::ok, "put route"));
    });
    // The port reads a connection as HTTP only when it starts like a standard method (tcp_listener.cpp:
    // garbage is dropped at once instead of waiting for a header): a custom method gets no answer.
    {
        boost::asio::io_context io;
        tcp::socket sock(io);
        sock.connect(tcp::endpoint(boost::asio::ip::make_address("127.0.0.1"), f.port));
        boost::asio::write(sock, boost::asio::buffer(std::string("BREW /any HTTP/1.1\r\nHost: localhost\r\n\r\n")));
        std::array<char, 64> buf{};
        boost::system::error_code ec;
        const std::size_t n = sock.read_some(boost::asio::buffer(buf), ec);
        CHECK(n == 0);
        // EOF, or a reset: the unread rest of the request is still in the port's receive buffer.
        CHECK((ec == boost::asio::error::eof || ec == boost::asio::error::connection_reset));
    }
    for (const char* method : {"GET", "DELETE", "PATCH", "OPTIONS", "PUT"}) {
        boost::asio::io_context io;
        beast::tcp_stream s(io);
        s.connect(tcp::endpoint(boost::asio::ip::make_address("127.0.0.1"), f.port));
        bhttp::request<bhttp::string_body> req;
        req.method_string(method);
        req.target("/any");
        req.version(11);
        req.set(bhttp::field::host, "localhost");
        bhttp::write(s, req);
        beast::flat_buffer b;
        bhttp::response<bhttp::string_body> r;
        bhttp::read(s, b, r);
        CHECK(r.result() == bhttp::status::ok);
        CHECK(r.body() == (std::string(method) == "PUT" ? std::string("put route") : std::string(method)));
    }
}

TEST_CASE("RR messages travel over a WebSocket with the RR subprotocol, or none") {
    Fixture f;
    const bool named = GENERATE(true, false);
    INFO((named ? "subprotocol robotraconteur.robotraconteur.com" : "no subprotocol"));
    boost::asio::io_context io;
    websocket::stream<beast::tcp_stream> ws(io);
    beast::get_lowest_layer(ws).connect(tcp::endpoint(boost::asio::ip::make_address("127.0.0.1"), f.port));
    if (named)
        ws.set_option(websocket::stream_base::decorator([](websocket::request_type& req) {
            req.set(bhttp::field::sec_websocket_protocol, "robotraconteur.robotraconteur.com");
        }));
    websocket::response_type res;
    ws.handshake(res, "localhost", "/");
    CHECK(res[bhttp::field::sec_websocket_protocol] == (named ? "robotraconteur.robotraconteur.com" : ""));
    ws.binary(true);

    ClientSessionConfig cfg;
    cfg.stream.local_node_id = *NodeID::parse("11111111-2222-3333-4444-555555555555");
    cfg.service_name = "ws";
    cfg.local_endpoint = 99;
    auto now = std::chrono::steady_clock::now();
    ClientSession session(cfg, now);
    auto exchange = [&] {
        auto out = session.pending_output();
        if (!out.empty()) {
            // Split in two frames: frame boundaries carry no meaning.
            auto half = out.size() / 2;
            ws.write(boost::asio::buffer(out.data(), half));
            ws.write(boost::asio::buffer(out.data() + half, out.size() - half));
            session.consume_output(out.size());
        }
        beast::flat_buffer b;
        ws.read(b);
        auto data = b.data();
        REQUIRE(session.feed(std::span<const std::byte>(static_cast<const std::byte*>(data.data()), data.size()), now));
    };
    for (int i = 0; i < 10 && !session.is_connected(); ++i) exchange();
    REQUIRE(session.is_connected());
    CHECK(session.info().object_type == "example.wstest.Obj");

    MessageEntry get;
    get.entry_type = MessageEntryType::PropertyGetReq;
    get.service_path = "ws";
    get.member_name = "x";
    auto id = session.request(MessageEntry(get), now);
    REQUIRE(id);
    std::optional<ClientResponse> reply;
    for (int i = 0; i < 10 && !reply; ++i) {
        exchange();
        while (auto ev = session.poll_event())
            if (auto* r = std::get_if<ClientResponse>(&*ev)) reply = std::move(*r);
    }
    REQUIRE(reply);
    REQUIRE(reply->entry);
    double v = 0;
    CHECK(read_scalar(*reply->entry->find("value"), v));
    CHECK(v == 3.25);
}
