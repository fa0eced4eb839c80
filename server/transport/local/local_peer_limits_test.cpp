// The hostile-peer cases the TCP port survives (server/service/peer_limits_test.cpp), over rr+local:
// a message over 512 KiB before the client session exists, max_message_size once it exists, wrong magic and a truncated message inside an
// established stream, an unknown special request, max_connections, a peer that never speaks and one
// that speaks something else than RR. Other clients stay unaffected.
#include <catch2/catch.hpp>

#include <cstring>
#include <future>
#include <thread>

#include <boost/asio/local/stream_protocol.hpp>
#include <boost/asio/write.hpp>

#include "core/session/elements.hpp"
#include "core/session/stream_connection.hpp"
#include "server/client/client.hpp"
#include "server/client/raw_client.hpp"
#include "server/node/node.hpp"
#include "server/service/test_raw_service.hpp"
#include "server/transport/local/local_connector.hpp"
#include "server/transport/local/local_listener.hpp"
#include "server/transport/local/local_test_support.hpp"
#include "server/transport/local/node_identity.hpp"
#include "server/transport/test_raw_stream.hpp"
#include "test/support/eventually.hpp"

using namespace rr;
using namespace rr::server;
using namespace rr::server::local;
using namespace std::chrono_literals;
namespace asio = boost::asio;
using unix_socket = asio::local::stream_protocol;

namespace {

struct LocalNode {
    local::testing::TempNodeDirs tmp;
    std::shared_ptr<Node> node;
    std::shared_ptr<LocalListener> listener;

    explicit LocalNode(NodeOptions options) {
        options.node_name = local::testing::unique_node_name("limits.local");
        options.threads = 2;
        auto r = reserve_node_name(tmp.dirs, options.node_name);
        REQUIRE(r);
        options.node_id = r->node_id;
        node = Node::create(options);
        REQUIRE(node->register_service(std::make_shared<server::testing::RawTestService>()));
        LocalListenOptions lo;
        lo.dirs = tmp.dirs;
        auto l = listen_local(node, lo, std::move(*r));
        REQUIRE(l);
        listener = *l;
    }
    ~LocalNode() {
        listener->close();
        node->shutdown();
    }
    std::string url() const { return "rr+local:///?nodename=" + node->node_name() + "&service=svc"; }
};

// A raw client-role stream to the node's Unix socket.
struct RawStream : server::testing::RawStream<unix_socket> {
    RawStream(const std::string& path, StreamConfig config, bool handshake = true)
        : server::testing::RawStream<unix_socket>(unix_socket::endpoint(path), std::move(config), handshake) {}
};
using server::testing::framed;
using server::testing::is_closed_event;
using server::testing::reply_entry;

// A well-behaved typed client through the node's rr+local entries.
void check_others_unaffected(LocalNode& n) {
    default_transports().add("rr+local", std::make_shared<LocalConnector>([d = n.tmp.dirs] { return d; }));
    client::IoThreads io{1};
    auto c = client::Client::connect(io.executor(), n.url());
    default_transports().add("rr+local", std::make_shared<LocalConnector>());
    REQUIRE(c);
    auto x = (*c)->root().get("x");
    REQUIRE(x);
    CHECK(*x == Value::scalar(42.5));
    CHECK((*c)->close_wait().ok());
}

}  // namespace

TEST_CASE("local limits: a message over 512 KiB before the client session exists closes the connection") {
    LocalNode n({});
    StreamConfig big;
    big.limits.max_pre_session_message_size = 4u << 20;
    RawStream under(n.listener->socket_path(), big);
    under.send_special(MessageEntryType::GetServiceDesc, "svc", 400u * 1024u);
    auto r = under.next_event(30s);
    const MessageEntry* reply = reply_entry(r);
    REQUIRE(reply);
    CHECK(reply->entry_type == MessageEntryType::GetServiceDescRet);
    CHECK(reply->error == MessageErrorType::None);

    RawStream over(n.listener->socket_path(), big);
    over.send_special(MessageEntryType::GetServiceDesc, "svc", 600u * 1024u);
    CHECK(is_closed_event(over.next_event(30s)));
    check_others_unaffected(n);
}

TEST_CASE("local limits: max_message_size is configurable and applies once the session exists") {
    NodeOptions options;
    options.server.stream.limits.max_message_size = 1u << 20;
    LocalNode n(options);
    default_transports().add("rr+local", std::make_shared<LocalConnector>([d = n.tmp.dirs] { return d; }));
    client::IoThreads io{1};
    auto connect = [&] {
        std::promise<Result<std::shared_ptr<RawClient>>> p;
        RawClient::connect(io.executor(), *parse_connection_url(n.url()), {}, {}, {},
                           [&](Result<std::shared_ptr<RawClient>> r) { p.set_value(std::move(r)); });
        return p.get_future().get();
    };
    auto call = [](RawClient& c, std::size_t padding) {
        std::promise<Result<MessageEntry>> p;
        c.request(server::testing::padded_get(padding), [&](Result<MessageEntry> r) { p.set_value(std::move(r)); });
        return p.get_future().get();
    };
    auto c = connect();
    default_transports().add("rr+local", std::make_shared<LocalConnector>());
    REQUIRE(c);
    // 700 KiB: over the pre-session limit, under the configured one: answered.
    auto ok = call(**c, 700u * 1024u);
    REQUIRE(ok);
    CHECK(ok->error == MessageErrorType::None);
    // 2 MiB: over the configured limit: the node drops the connection.
    auto over = call(**c, 2u << 20);
    REQUIRE_FALSE(over);
    CHECK(over.error().type == MessageErrorType::ConnectionError);
    CHECK(rr::testing::eventually([&] { return !(*c)->is_open(); }));
    check_others_unaffected(n);
}

// [timing]: it measures a rate.
TEST_CASE("local limits: messages_per_second paces a flooding client over rr+local", "[timing]") {
    // gateway.limits' rates apply to every accepted connection, the Unix socket's too (transport.hpp).
    NodeOptions options;
    options.read_rates.messages_per_second = 20;
    options.read_rates.burst_s = 1;
    LocalNode n(options);
    default_transports().add("rr+local", std::make_shared<LocalConnector>([d = n.tmp.dirs] { return d; }));
    client::IoThreads io{1};
    auto c = client::Client::connect(io.executor(), n.url());
    default_transports().add("rr+local", std::make_shared<LocalConnector>());
    REQUIRE(c);
    std::this_thread::sleep_for(1200ms);  // the bucket full again after the handshake
    int calls = 0;
    const auto t0 = std::chrono::steady_clock::now();
    while (std::chrono::steady_clock::now() - t0 < 2s) {
        REQUIRE((*c)->root().get("x"));
        ++calls;
    }
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    INFO(calls << " calls in " << elapsed << " s");
    CHECK(calls <= 20 * (elapsed + 1) + 5);  // the 1-second burst plus the rate
    CHECK(calls >= 10 * elapsed);             // slowed, not stopped
    CHECK(n.node->reads_throttled() > 0);
    CHECK((*c)->close_wait().ok());
}

TEST_CASE("local limits: wrong magic, a truncated message, an unknown special request") {
    LocalNode n({});
    SECTION("wrong magic") {
        RawStream s(n.listener->socket_path(), {});
        s.write_raw(framed("RRAX", 64));
        CHECK(is_closed_event(s.next_event(30s)));
    }
    SECTION("truncated: MessageSize covers the bytes, the entries inside do not fit") {
        RawStream s(n.listener->socket_path(), {});
        std::vector<std::byte> bad = framed("RRAC", 60);
        bad[8] = std::byte{2};
        bad[10] = std::byte{52};
        bad[56] = std::byte{3};
        s.write_raw(bad);
        CHECK(is_closed_event(s.next_event(30s)));
    }
    SECTION("unknown special request: answered with ProtocolError, the stream stays up") {
        RawStream s(n.listener->socket_path(), {});
        s.send_special(static_cast<MessageEntryType>(151), "svc", 0);
        auto r = s.next_event(30s);
        const MessageEntry* reply = reply_entry(r);
        REQUIRE(reply);
        CHECK(reply->error == MessageErrorType::ProtocolError);
        s.send_special(MessageEntryType::GetServiceDesc, "svc", 0);
        auto next = s.next_event(30s);
        const MessageEntry* desc = reply_entry(next);
        REQUIRE(desc);
        CHECK(desc->entry_type == MessageEntryType::GetServiceDescRet);
    }
    check_others_unaffected(n);
}

TEST_CASE("local limits: a silent peer and a peer speaking something else are dropped") {
    NodeOptions o;
    o.first_bytes_timeout = 3000ms;  // the honest client of check_others_unaffected() meets it under load
    LocalNode n(o);
    SECTION("silent") {
        RawStream s(n.listener->socket_path(), {}, false);
        auto t0 = std::chrono::steady_clock::now();
        CHECK(s.closed_by_peer(30s));
        CHECK(std::chrono::steady_clock::now() - t0 >= 250ms);
    }
    SECTION("HTTP on the local socket") {
        RawStream s(n.listener->socket_path(), {}, false);
        const std::string get = "GET / HTTP/1.1\r\n\r\n";
        std::vector<std::byte> bytes(get.size());
        std::memcpy(bytes.data(), get.data(), get.size());
        s.write_raw(bytes);
        CHECK(s.closed_by_peer(30s));
    }
    check_others_unaffected(n);
}

TEST_CASE("local limits: max_connections refuses further connections until one closes") {
    NodeOptions o;
    o.max_connections = 2;
    LocalNode n(o);
    auto a = std::make_unique<RawStream>(n.listener->socket_path(), StreamConfig{});
    auto b = std::make_unique<RawStream>(n.listener->socket_path(), StreamConfig{});
    CHECK(rr::testing::eventually([&] { return n.node->connection_count() >= 2; }));
    CHECK(n.node->connection_count() == 2);
    RawStream third(n.listener->socket_path(), {}, false);
    CHECK(third.closed_by_peer(30s));
    a.reset();
    CHECK(rr::testing::eventually([&] { return n.node->connection_count() < 2; }));
    check_others_unaffected(n);
}
