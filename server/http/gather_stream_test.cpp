// GatherStream under Beast's websocket::stream, over real loopback TCP: gathered frames are Beast's own
// bytes and leave in one write; a layer below that takes a few bytes per write; a kernel that takes part
// of a batch; Beast's own writes queued behind a batch in order; the first error kept and given once
// to each waiter.
#include <catch2/catch.hpp>

#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <sys/socket.h>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/read.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>

#include "server/http/gather_stream.hpp"

// At namespace scope, as the other server tests (a unity build may put them in one translation unit).
namespace asio = boost::asio;
namespace beast = boost::beast;
namespace websocket = boost::beast::websocket;
using tcp = boost::asio::ip::tcp;
using rr::server::http::GatherStream;

namespace {

using error_code = boost::system::error_code;

/// A layer that takes at most `max_write` bytes per write (a kernel that takes part of what it is
/// given, every time) and counts its writes.
template <class Next>
class Trickle {
public:
    using executor_type = typename Next::executor_type;
    explicit Trickle(Next next) : next_(std::move(next)) {}
    executor_type get_executor() { return next_.get_executor(); }
    Next& next_layer() { return next_; }
    template <class B, class H>
    auto async_read_some(const B& b, H&& h) { return next_.async_read_some(b, std::forward<H>(h)); }
    template <class B, class H>
    auto async_write_some(const B& b, H&& h) {
        ++writes;
        return next_.async_write_some(head(b), std::forward<H>(h));
    }
    template <class B>
    std::size_t read_some(const B& b) { return next_.read_some(b); }
    template <class B>
    std::size_t read_some(const B& b, error_code& ec) { return next_.read_some(b, ec); }
    template <class B>
    std::size_t write_some(const B& b) { return next_.write_some(head(b)); }
    template <class B>
    std::size_t write_some(const B& b, error_code& ec) { return next_.write_some(head(b), ec); }

    std::size_t max_write = 7;
    int writes = 0;

private:
    // At most max_write bytes of the first non-empty buffer.
    template <class B>
    asio::const_buffer head(const B& b) const {
        for (auto it = asio::buffer_sequence_begin(b); it != asio::buffer_sequence_end(b); ++it) {
            asio::const_buffer one(*it);
            if (one.size() > 0) return asio::const_buffer(one.data(), std::min(one.size(), max_write));
        }
        return {};
    }

    Next next_;
};
template <class Next, class H>
void async_teardown(beast::role_type role, Trickle<Next>& s, H&& h) {
    using beast::websocket::async_teardown;
    async_teardown(role, s.next_layer(), std::forward<H>(h));
}

/// A server-role WebSocket of type `ServerWs` and a Beast client, connected over loopback, handshake done.
template <class ServerWs>
struct WsPair {
    asio::io_context io;
    std::optional<ServerWs> server;
    websocket::stream<beast::tcp_stream> client{io};

    WsPair() {
        tcp::acceptor acceptor(io, tcp::endpoint(asio::ip::make_address("127.0.0.1"), 0));
        tcp::socket s(io);
        beast::get_lowest_layer(client).connect(acceptor.local_endpoint());
        acceptor.accept(s);
        server.emplace(beast::tcp_stream(std::move(s)));
        int done = 0;
        server->async_accept([&](error_code ec) {
            REQUIRE_FALSE(ec);
            ++done;
        });
        client.async_handshake("127.0.0.1", "/", [&](error_code ec) {
            REQUIRE_FALSE(ec);
            ++done;
        });
        io.run();
        io.restart();
        REQUIRE(done == 2);
        server->auto_fragment(false);  // as the JSON session: one frame per message
        // Room in the kernel for a test's whole batch while nobody reads (the defaults start at 16 KiB).
        beast::get_lowest_layer(*server).socket().set_option(asio::socket_base::send_buffer_size(1 << 20));
        client_socket().set_option(asio::socket_base::receive_buffer_size(1 << 20));
    }

    tcp::socket& client_socket() { return beast::get_lowest_layer(client).socket(); }

    /// Exactly `n` raw bytes from the client's socket (blocking).
    std::string read_raw(std::size_t n) {
        std::string out(n, '\0');
        asio::read(client_socket(), asio::buffer(out));
        return out;
    }
};

struct Msg {
    std::string bytes;
    bool binary;
};

/// Messages of the frame-length forms (7-bit, 16-bit, 64-bit lengths), text and binary.
std::vector<Msg> sample_messages() {
    std::vector<Msg> out;
    for (std::size_t size : {0u, 1u, 125u, 126u, 127u, 300u, 65535u, 65536u})
        out.push_back({std::string(size, static_cast<char>('a' + size % 26)), false});
    out.push_back({std::string("\x00\x01\x02\xff binary", 11), true});
    for (int i = 0; i < 40; ++i) out.push_back({"{\"subscription\":1,\"kind\":\"wire\",\"value\":" + std::to_string(i) + "}", false});
    return out;
}

std::size_t total_frame_bytes(const std::vector<Msg>& ms) {
    std::size_t n = 0;
    for (const auto& m : ms) n += m.bytes.size() + (m.bytes.size() < 126 ? 2 : m.bytes.size() < 65536 ? 4 : 10);
    return n;
}

template <class Ws>
void write_all(Ws& ws, const std::vector<Msg>& ms) {
    for (const auto& m : ms) {
        ws.binary(m.binary);
        error_code ec;
        ws.write(asio::buffer(m.bytes), ec);
        REQUIRE_FALSE(ec);
    }
}

// Reads ms.size() messages; one word per message ("ok", "wrong type", "wrong bytes", or the read's
// error). No Catch assertion here: a reader thread may call it (Catch's assertions are not thread-safe).
template <class Client>
std::vector<std::string> read_all(Client& client, const std::vector<Msg>& ms) {
    std::vector<std::string> got;
    for (const auto& m : ms) {
        beast::flat_buffer b;
        error_code e;
        client.read(b, e);
        if (e) {
            got.push_back("error " + e.message());
            break;
        }
        if (client.got_binary() != m.binary)
            got.push_back("wrong type");
        else
            got.push_back(beast::buffers_to_string(b.data()) == m.bytes ? "ok" : "wrong bytes");
    }
    return got;
}

template <class Client>
void read_all_in_order(Client& client, const std::vector<Msg>& ms) {
    CHECK(read_all(client, ms) == std::vector<std::string>(ms.size(), "ok"));
}

}  // namespace

TEST_CASE("GatherStream: messages gathered under Beast leave in one write, byte for byte Beast's frames") {
    const auto ms = sample_messages();
    const std::size_t total = total_frame_bytes(ms);

    // Beast writing each frame to the socket itself: the reference bytes.
    WsPair<websocket::stream<beast::tcp_stream>> plain;
    write_all(*plain.server, ms);
    const std::string reference = plain.read_raw(total);

    WsPair<websocket::stream<GatherStream<beast::tcp_stream>>> gathered;
    auto& layer = gathered.server->next_layer();
    layer.max_gathered(1 << 20);  // the whole sample in one batch
    const auto writes_before = layer.writes();
    write_all(*gathered.server, ms);
    CHECK(layer.gathered() == total);
    CHECK(layer.writes() == writes_before);  // nothing reached the kernel yet
    error_code ec;
    CHECK(layer.write_now(ec));  // one non-blocking write took it all
    CHECK_FALSE(ec);
    CHECK(layer.writes() == writes_before + 1);
    CHECK(layer.gathered() == 0);
    CHECK(layer.idle());
    CHECK(gathered.read_raw(total) == reference);

    // And a Beast client reads them as messages, in order.
    write_all(*gathered.server, ms);
    CHECK(layer.write_now(ec));
    CHECK(layer.writes() == writes_before + 2);
    read_all_in_order(gathered.client, ms);
}

TEST_CASE("GatherStream: a layer below that takes 7 bytes per write gets every byte, in order, asynchronously") {
    WsPair<websocket::stream<GatherStream<Trickle<beast::tcp_stream>>>> pair;
    auto& layer = pair.server->next_layer();
    const auto ms = sample_messages();
    const std::vector<Msg> first(ms.begin(), ms.begin() + 5), second(ms.begin() + 5, ms.end());

    const int handshake_writes = layer.next_layer().writes;
    write_all(*pair.server, first);
    error_code ec;
    CHECK_FALSE(layer.write_now(ec));  // not a TCP stream: no synchronous write; nothing written yet
    CHECK_FALSE(ec);
    CHECK(layer.next_layer().writes == handshake_writes);
    bool flushed = false;
    layer.async_flush([&](error_code e) {
        CHECK_FALSE(e);
        flushed = true;
    });
    CHECK_FALSE(flushed);  // never inside the call
    // Beast's own write (a ping) while the batch is being written: it goes after the batch.
    bool pinged = false;
    pair.server->async_ping({}, [&](error_code e) {
        CHECK_FALSE(e);
        pinged = true;
    });
    // More frames gathered behind both; the next flush writes them.
    write_all(*pair.server, second);
    bool flushed2 = false;
    layer.async_flush([&](error_code e) {
        CHECK_FALSE(e);
        flushed2 = true;
    });

    // The client reads on a thread of its own while the server's io_context writes.
    std::vector<std::string> events;
    pair.client.control_callback([&](websocket::frame_type kind, beast::string_view) {
        if (kind == websocket::frame_type::ping) events.push_back("ping");
    });
    std::thread reader([&] {
        for (const auto& m : ms) {
            beast::flat_buffer b;
            error_code e;
            pair.client.read(b, e);
            if (e) {
                events.push_back("error " + e.message());
                return;
            }
            events.push_back(beast::buffers_to_string(b.data()) == m.bytes ? "ok" : "wrong bytes");
        }
    });
    pair.io.run();
    reader.join();
    CHECK(flushed);
    CHECK(pinged);
    CHECK(flushed2);
    std::vector<std::string> expected(first.size(), "ok");
    expected.push_back("ping");
    expected.insert(expected.end(), second.size(), "ok");
    CHECK(events == expected);
    CHECK(layer.next_layer().writes - handshake_writes >= static_cast<int>(total_frame_bytes(ms) / 7));
    CHECK(layer.idle());
}

TEST_CASE("GatherStream: what the kernel does not take at once is written asynchronously, and the rest queues behind") {
    WsPair<websocket::stream<GatherStream<beast::tcp_stream>>> pair;
    auto& layer = pair.server->next_layer();
    layer.max_gathered(std::size_t{8} << 20);
    // A small send buffer, and the client not reading yet: a 2 MiB batch cannot go in one write.
    auto& socket = beast::get_lowest_layer(*pair.server).socket();
    socket.set_option(asio::socket_base::send_buffer_size(16 * 1024));
    pair.client_socket().set_option(asio::socket_base::receive_buffer_size(16 * 1024));
    std::vector<Msg> ms;
    for (int i = 0; i < 32; ++i) ms.push_back({std::to_string(i) + std::string(64 * 1024, 'x'), false});
    write_all(*pair.server, ms);
    error_code ec;
    CHECK_FALSE(layer.write_now(ec));  // part written, the rest waits
    CHECK_FALSE(ec);
    CHECK(layer.gathered() > 0);
    CHECK(layer.gathered() < total_frame_bytes(ms));
    bool flushed = false;
    layer.async_flush([&](error_code e) {
        CHECK_FALSE(e);
        flushed = true;
    });
    CHECK_FALSE(layer.idle());
    CHECK_FALSE(layer.write_now(ec));  // a write is in flight: nothing synchronous now
    std::vector<std::string> got;
    std::thread reader([&] { got = read_all(pair.client, ms); });
    pair.io.run();
    reader.join();
    CHECK(got == std::vector<std::string>(ms.size(), "ok"));
    CHECK(flushed);
    CHECK(layer.idle());
}

TEST_CASE("GatherStream: the first write error is kept and given once to each waiter, later writes fail at once") {
    WsPair<websocket::stream<GatherStream<beast::tcp_stream>>> pair;
    auto& layer = pair.server->next_layer();
    // The client resets the connection (SO_LINGER 0): the server's writes fail from the next one on.
    pair.client_socket().set_option(asio::socket_base::linger(true, 0));
    pair.client_socket().close();
    error_code ec;
    for (int i = 0; i < 100 && !ec; ++i) {
        error_code wec;
        pair.server->write(asio::buffer(std::string(1000, 'z')), wec);
        if (wec) {
            ec = wec;
            break;
        }
        layer.write_now(ec);
    }
    REQUIRE(ec);
    CHECK(layer.error() == ec);
    CHECK_FALSE(layer.idle());
    // Later writes: the same error, at once; a flush completes with it, but not inside the call.
    error_code again;
    CHECK(layer.write_now(again));
    CHECK(again == ec);
    CHECK(layer.write_some(asio::buffer("x", 1), again) == 0);
    CHECK(again == ec);
    int calls = 0;
    error_code flushed;
    layer.async_flush([&](error_code e) {
        ++calls;
        flushed = e;
    });
    CHECK(calls == 0);
    pair.io.run();
    CHECK(calls == 1);
    CHECK(flushed == ec);
}

TEST_CASE("GatherStream: a batch whose asynchronous write fails gives the error to its flush and to the write behind it") {
    WsPair<websocket::stream<GatherStream<Trickle<beast::tcp_stream>>>> pair;
    auto& layer = pair.server->next_layer();
    pair.client_socket().set_option(asio::socket_base::linger(true, 0));
    pair.client_socket().close();
    // Enough bytes that the 7-byte writes meet the reset.
    write_all(*pair.server, std::vector<Msg>(50, Msg{std::string(2000, 'q'), false}));
    int flush_calls = 0, write_calls = 0;
    error_code flush_ec, write_ec;
    layer.async_flush([&](error_code e) {
        ++flush_calls;
        flush_ec = e;
    });
    pair.server->async_ping({}, [&](error_code e) {  // Beast's write, behind the batch
        ++write_calls;
        write_ec = e;
    });
    pair.io.run();
    CHECK(flush_calls == 1);
    CHECK(flush_ec);
    CHECK(write_calls == 1);
    CHECK(write_ec);
    CHECK(layer.error() == flush_ec);
}

TEST_CASE("GatherStream: a buffer that reaches max_gathered starts its write by itself, the rest follows in order") {
    WsPair<websocket::stream<GatherStream<beast::tcp_stream>>> pair;
    auto& layer = pair.server->next_layer();
    layer.max_gathered(100);
    const auto writes_before = layer.writes();
    const std::vector<Msg> ms{{std::string(60, 'a'), false}, {std::string(60, 'b'), false}, {std::string(60, 'c'), false}};
    write_all(*pair.server, {ms[0]});
    CHECK(layer.writes() == writes_before);
    CHECK_FALSE(layer.full());
    write_all(*pair.server, {ms[1]});  // 124 bytes gathered: the layer writes them
    CHECK(layer.writes() == writes_before + 1);
    CHECK(layer.gathered() == 0);
    CHECK_FALSE(layer.idle());
    write_all(*pair.server, {ms[2]});  // behind the write in flight
    CHECK(layer.gathered() == 62);
    bool flushed = false;
    layer.async_flush([&](error_code e) {
        CHECK_FALSE(e);
        flushed = true;
    });
    pair.io.run();
    CHECK(flushed);
    CHECK(layer.idle());
    read_all_in_order(pair.client, ms);
}
