// The HTTP and WebSocket sessions of HttpServer, as templates over the byte stream: Beast's TCP stream
// (plain HTTP, ws://) is instantiated in http_server.cpp, TlsStream (HTTPS, wss://) in
// http_server_tls.cpp. Private to server/http.
#pragma once

#include <array>
#include <atomic>
#include <algorithm>
#include <cstring>
#include <mutex>
#include <fstream>
#include <optional>
#include <sstream>
#include <type_traits>
#include <utility>

#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>

#include <boost/asio/bind_allocator.hpp>
#include <boost/asio/ssl/error.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <boost/circular_buffer.hpp>

#include "server/common/handler_memory.hpp"
#include "server/common/read_throttle.hpp"
#include "server/http/gather_stream.hpp"
#include "server/http/http_server.hpp"
#include "server/node/node.hpp"
#include "server/transport/websocket_byte_stream.hpp"

namespace rr::server::http::detail {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace bhttp = boost::beast::http;
namespace websocket = boost::beast::websocket;
using tcp = asio::ip::tcp;

inline constexpr std::string_view kRRSubprotocol = "robotraconteur.robotraconteur.com";


inline char lower(char c) { return (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c; }

inline bool iequals(std::string_view a, std::string_view b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i)
        if (lower(a[i]) != lower(b[i])) return false;
    return true;
}

inline std::vector<std::string_view> split_list(std::string_view s) {
    std::vector<std::string_view> out;
    while (!s.empty()) {
        auto comma = s.find(',');
        auto item = s.substr(0, comma);
        while (!item.empty() && (item.front() == ' ' || item.front() == '\t')) item.remove_prefix(1);
        while (!item.empty() && (item.back() == ' ' || item.back() == '\t')) item.remove_suffix(1);
        if (!item.empty()) out.push_back(item);
        if (comma == std::string_view::npos) break;
        s.remove_prefix(comma + 1);
    }
    return out;
}

inline std::string_view mime_type(std::string_view path) {
    auto dot = path.rfind('.');
    auto ext = dot == std::string_view::npos ? std::string_view{} : path.substr(dot);
    if (ext == ".html" || ext == ".htm") return "text/html; charset=utf-8";
    if (ext == ".js" || ext == ".mjs") return "text/javascript; charset=utf-8";
    if (ext == ".css") return "text/css; charset=utf-8";
    if (ext == ".json" || ext == ".map") return "application/json";
    if (ext == ".wasm") return "application/wasm";
    if (ext == ".svg") return "image/svg+xml";
    if (ext == ".png") return "image/png";
    if (ext == ".ico") return "image/x-icon";
    if (ext == ".ts" || ext == ".txt" || ext == ".md" || ext == ".robdef") return "text/plain; charset=utf-8";
    return "application/octet-stream";
}

// Maps a URL path to a file under root; rejects anything that could leave it.
inline std::optional<std::string> static_path(const std::string& root, std::string_view target) {
    auto q = target.find_first_of("?#");
    std::string_view path = target.substr(0, q);
    if (path.empty() || path.front() != '/') return std::nullopt;
    if (path.find("..") != std::string_view::npos || path.find('\\') != std::string_view::npos ||
        path.find('\0') != std::string_view::npos)
        return std::nullopt;
    std::string full = root + std::string(path);
    if (full.back() == '/') full += "index.html";
    return full;
}

/// Paces one connection's reads by the node's per-connection rates (gateway.limits messages_per_second
/// and bytes_per_second, Node::make_read_throttle): every message read is charged, and the next read
/// waits as long as the throttle says (back-pressure; nothing is dropped). Without rates: no cost.
/// Used on the connection's own strand only.
class ReadPacer {
public:
    ReadPacer(const std::shared_ptr<Node>& node, const asio::any_io_executor& executor)
        : node_(node), throttle_(node ? node->make_read_throttle() : nullptr), timer_(executor) {}

    /// A message of `bytes` was read from `peer`.
    void charge(std::size_t bytes, const std::string& peer) {
        if (!throttle_) return;
        pause_ = throttle_->charge_message(bytes, ReadThrottle::Clock::now());
        if (pause_ > std::chrono::nanoseconds::zero())
            if (auto n = node_.lock()) n->read_throttled(peer);
    }
    /// Runs `read` now, or after the pause the last charge asked for.
    template <class Read>
    void then(Read read) {
        if (pause_ <= std::chrono::nanoseconds::zero()) return read();
        timer_.expires_after(std::exchange(pause_, std::chrono::nanoseconds::zero()));
        timer_.async_wait([read = std::move(read)](beast::error_code) mutable { read(); });
    }
    void cancel() { timer_.cancel(); }

private:
    std::weak_ptr<Node> node_;
    std::unique_ptr<ReadThrottle> throttle_;
    asio::steady_timer timer_;
    std::chrono::nanoseconds pause_{0};
};

/// A JSON-subprotocol WebSocket session: text frames both ways, bounded outgoing queue.
///
/// Messages sent from any thread wait in `incoming_` (under a mutex) until the session's strand takes
/// them, woken once per batch: a value fanned out to many sockets costs each one a queued message and
/// at most one wake, not a closure per message. The wake and the asynchronous write live in the
/// session's HandlerMemory (issue 14: Asio's per-thread cache missed on every cross-thread hand-off).
///
/// Gathered writes (HttpOptions::websocket_gathered_writes, issue 56): every message waiting, up to
/// kGatherBytes, is framed by Beast's synchronous write into the GatherStream below the WebSocket
/// (a copy, no kernel call), then all of them leave in one non-blocking write; what the kernel does not
/// take at once is written asynchronously before the next batch. Messages over kGatherMessageMax (camera
/// frames, binary pushes of large arrays) keep Beast's asynchronous write from their own buffers.
template <class Stream>
class JsonWebSocketSession : public JsonSocket, public std::enable_shared_from_this<JsonWebSocketSession<Stream>> {
public:
    using std::enable_shared_from_this<JsonWebSocketSession<Stream>>::shared_from_this;

    using WebSocket = websocket::stream<GatherStream<Stream>>;
    /// A message of at most this many bytes is gathered (copied); a larger one is written from its own buffers.
    static constexpr std::size_t kGatherMessageMax = 16 * 1024;
    /// A batch stops gathering once this many bytes wait (then flushes): at most this plus one message.
    static constexpr std::size_t kGatherBytes = 64 * 1024;

    JsonWebSocketSession(WebSocket ws, const JsonSocketHandler* handler, std::size_t limit, bool gather,
                         std::string peer, std::string cookie = {}, const std::shared_ptr<Node>& node = {},
                         std::string target = {}, std::string subprotocol = {})
        : ws_(std::move(ws)), handler_(handler), limit_(std::max<std::size_t>(limit, 1)), gather_(gather), peer_(std::move(peer)),
          cookie_(std::move(cookie)), target_(std::move(target)), subprotocol_(std::move(subprotocol)),
          pacer_(node, ws_.get_executor()), probe_timer_(ws_.get_executor()), goodbye_timer_(ws_.get_executor()) {
        const auto executor = ws_.get_executor();
        if (const auto* io = executor.template target<IoStrand>()) io_strand_ = *io;
        // The layer's own flush threshold stays above a batch (kGatherBytes plus one message and its
        // frame header): a batch leaves with write_now(), not with a write the layer starts itself.
        ws_.next_layer().max_gathered(kGatherBytes + kGatherMessageMax + 64);
    }

    void start() {
        ws_.text(true);
        ws_.auto_fragment(false);  // one frame per message, not Beast's 4 KiB fragments (one write each)
        // Any frame from the client counts for the liveness probe, a pong too.
        ws_.control_callback([this](websocket::frame_type, beast::string_view) { last_receive_ = std::chrono::steady_clock::now(); });
        if (handler_->on_open) handler_->on_open(shared_from_this());
        read();
    }

    void send(std::string text) override { enqueue(Outgoing::owned(std::move(text), false, false)); }
    void send_urgent(std::string text) override { enqueue(Outgoing::owned(std::move(text), true, false)); }
    void send_binary(std::string bytes) override { enqueue(Outgoing::owned(std::move(bytes), false, true)); }
    void send_binary(std::string head, std::shared_ptr<const std::string> tail) override {
        Outgoing out = Outgoing::owned(std::move(head), false, true);
        out.tail = std::move(tail);
        enqueue(std::move(out));
    }
    void send_shared(std::string_view head, std::shared_ptr<const std::string> body, std::size_t body_offset) override {
        Outgoing out;
        if (head.size() <= out.head.size()) {
            std::memcpy(out.head.data(), head.data(), head.size());
            out.head_size = static_cast<std::uint8_t>(head.size());
        } else {
            out.text.assign(head);
        }
        out.tail_offset = std::min(body_offset, body->size());
        out.tail = std::move(body);
        enqueue(std::move(out));
    }

    std::size_t queued() const override { return queued_count_.load(); }
    std::size_t queued_bytes() const override { return queued_bytes_.load(); }
    std::uint64_t dropped() const override { return dropped_.load(); }
    std::uint64_t writes() const override { return ws_.next_layer().writes(); }

    void close() override {
        auto self = shared_from_this();
        asio::post(ws_.get_executor(), [self] {
            if (self->closed_) return;
            self->closed_ = true;
            self->ws_.async_close(websocket::close_code::normal, [self](beast::error_code) {});
        });
    }

    void close_going_away() override {
        auto self = shared_from_this();
        asio::post(ws_.get_executor(), [self] {
            if (self->closed_ || self->finished_) return;
            // What is queued is not sent: the server is stopping. The handshake is bounded.
            self->fail(websocket::close_code::going_away, "server stopping", std::chrono::seconds(1));
        });
    }

    void set_liveness_probe(std::optional<std::chrono::milliseconds> timeout) override {
        auto self = shared_from_this();
        asio::post(ws_.get_executor(), [self, timeout] { self->probe(timeout); });
    }

    std::string peer() const override { return peer_; }
    /// Keeps `hold` alive as long as the session (the connection's per-address slot).
    void keep(std::shared_ptr<const void> hold) { hold_ = std::move(hold); }
    std::string cookie_header() const override { return cookie_; }
    std::string request_target() const override { return target_; }
    std::string subprotocol() const override { return subprotocol_; }

private:
    using IoStrand = asio::strand<asio::io_context::executor_type>;

    /// One message: `head` (inline, no allocation: a push's per-socket part), then `text`, then `tail`
    /// from `tail_offset` on, shared by every socket it goes to (a push's body, a binary push's arrays:
    /// written from one buffer for all subscribers, not copied per socket).
    struct Outgoing {
        std::array<char, 96> head;  // fits push_head()'s longest
        std::uint8_t head_size = 0;
        bool urgent = false;
        bool binary = false;
        std::string text;
        std::shared_ptr<const std::string> tail;
        std::size_t tail_offset = 0;

        static Outgoing owned(std::string text, bool urgent, bool binary) {
            Outgoing o;
            o.text = std::move(text);
            o.urgent = urgent;
            o.binary = binary;
            return o;
        }
        std::size_t size() const noexcept { return head_size + text.size() + (tail ? tail->size() - tail_offset : 0); }
        std::array<asio::const_buffer, 3> buffers() const noexcept {
            return {asio::buffer(head.data(), head_size), asio::buffer(text),
                    tail ? asio::buffer(tail->data() + tail_offset, tail->size() - tail_offset) : asio::const_buffer()};
        }
    };

    // Any thread. `incoming_` holds at most limit_ messages, like the queue (the same drop rule).
    void enqueue(Outgoing out) {
        queued_count_.fetch_add(1);
        queued_bytes_.fetch_add(out.size());
        bool wake = false;
        {
            std::lock_guard lock(incoming_mutex_);
            if (incoming_.size() >= limit_) drop_one(incoming_, 0);
            incoming_.push_back(std::move(out));
            wake = !wake_pending_;
            wake_pending_ = true;
        }
        if (wake) post_wake();
    }

    void post_wake() {
        auto self = shared_from_this();
        // Over the concrete strand when there is one: it queues the handler in the HandlerMemory, where
        // the type-erased executor would wrap it in a function object from Asio's per-thread cache.
        auto on_wake = asio::bind_allocator(allocator(), [self] { self->on_wake(); });
        if (io_strand_)
            asio::post(*io_strand_, std::move(on_wake));
        else
            asio::post(ws_.get_executor(), std::move(on_wake));
    }

    // On the strand: moves what arrived into the queue, then writes.
    void on_wake() {
        {
            std::lock_guard lock(incoming_mutex_);
            taken_.swap(incoming_);
            wake_pending_ = false;
        }
        for (auto& out : taken_) accept(std::move(out));
        taken_.clear();
        write();
    }

    void accept(Outgoing out) {
        if (closed_) {
            unqueue(out);
            return;
        }
        // Slow reader: the oldest waiting push (else the oldest waiting message) is dropped, and counted.
        const std::size_t busy = front_in_flight_ ? 1 : 0;
        if (queue_.size() >= limit_ && queue_.size() > busy) drop_one(queue_, busy);
        if (queue_.full()) queue_.set_capacity(std::min(std::max<std::size_t>(8, 2 * queue_.capacity()), limit_ + 1));
        if (out.urgent)
            queue_.insert(first_waiting_push(queue_, busy), std::move(out));
        else
            queue_.push_back(std::move(out));
    }

    // The first push from `skip` on: urgent messages go before it, behind earlier urgent ones.
    template <class Queue>
    static typename Queue::iterator first_waiting_push(Queue& q, std::size_t skip) {
        return std::find_if(q.begin() + skip, q.end(), [](const Outgoing& o) { return !o.urgent; });
    }

    // Drops the oldest push from `skip` on (else the message at `skip`) and counts it.
    template <class Queue>
    void drop_one(Queue& q, std::size_t skip) {
        auto victim = first_waiting_push(q, skip);
        if (victim == q.end()) victim = q.begin() + skip;
        unqueue(*victim);
        q.erase(victim);
        dropped_.fetch_add(1);
    }

    void read() {
        auto self = shared_from_this();
        pacer_.then([self] { self->read_now(); });
    }

    void read_now() {
        if (finished_) return;
        auto self = shared_from_this();
        ws_.async_read(buffer_, [self](beast::error_code ec, std::size_t) {
            if (ec) {
                self->finish();
                return;
            }
            self->last_receive_ = std::chrono::steady_clock::now();
            std::string text = beast::buffers_to_string(self->buffer_.data());
            self->buffer_.consume(self->buffer_.size());
            // Beast 1.81 checks UTF-8 per frame and misses a text message that ends inside a UTF-8
            // sequence when its last frame is empty (read.hpp calls finish() only after copying bytes).
            // RFC 6455 §8.1: fail the connection with 1007, as for invalid UTF-8 anywhere else.
            if (self->ws_.got_text() && !websocket::detail::check_utf8(text.data(), text.size())) {
                self->fail(websocket::close_code::bad_payload, "invalid UTF-8 in a text message");
                return;
            }
            self->pacer_.charge(text.size(), self->peer_);
            if (!self->ws_.got_text() && self->handler_->on_binary)
                self->handler_->on_binary(self, std::move(text));
            else if (self->handler_->on_message)
                self->handler_->on_message(self, std::move(text));
            self->read();
        });
    }

    // --- liveness probe (on the strand) ---

    void probe(std::optional<std::chrono::milliseconds> timeout) {
        ++probe_gen_;
        probe_timeout_ = timeout;
        probe_timer_.cancel();
        if (!timeout || finished_ || timeout->count() <= 0) return;
        probe_started_ = std::chrono::steady_clock::now();
        probe_tick(probe_gen_);
    }

    void probe_tick(std::uint64_t gen) {
        if (gen != probe_gen_ || finished_ || closed_ || !probe_timeout_) return;
        const auto now = std::chrono::steady_clock::now();
        if (now - std::max(last_receive_, probe_started_) >= *probe_timeout_) {
            // Nothing came back for the bound: the client counts as gone now (on_close), and the
            // connection is dropped without waiting for a close handshake that cannot come.
            finish();
            beast::error_code ec;
            beast::get_lowest_layer(ws_).socket().close(ec);
            return;
        }
        if (!ping_in_flight_) {
            ping_in_flight_ = true;
            auto self = shared_from_this();
            ws_.async_ping({}, [self](beast::error_code) { self->ping_in_flight_ = false; });
        }
        probe_timer_.expires_after(*probe_timeout_ / 5);
        auto self = shared_from_this();
        probe_timer_.async_wait([self, gen](beast::error_code ec) {
            if (!ec) self->probe_tick(gen);
        });
    }

    // Ends the WebSocket with a close frame carrying `code`; after `bound` the socket is closed without
    // waiting further. The bound is a timer of the session's own: the stream's expiry cannot be changed
    // while a read and a write are both pending (Beast asserts), as when a stopping server ends an
    // active socket (close_going_away) in the middle of a push.
    void fail(websocket::close_code code, const char* reason, std::chrono::milliseconds bound = std::chrono::seconds(5)) {
        auto self = shared_from_this();
        closed_ = true;
        goodbye_timer_.expires_after(bound);
        goodbye_timer_.async_wait([self](beast::error_code ec) {
            if (ec) return;
            self->finish();
            beast::error_code ignored;
            beast::get_lowest_layer(self->ws_).socket().close(ignored);
        });
        ws_.async_close(websocket::close_reason(code, reason), [self](beast::error_code) {
            self->goodbye_timer_.cancel();
            self->finish();
        });
    }

    void write() {
        if (writing_ || queue_.empty() || closed_) return;
        // Gathered only while nothing else is on its way through the layer (a pong, a ping: Beast's own
        // writes) and the WebSocket is open (no close frame sent: nothing may follow one).
        if (gather_ && queue_.front().size() <= kGatherMessageMax && ws_.is_open() && ws_.next_layer().idle())
            return write_gathered();
        writing_ = true;
        front_in_flight_ = true;
        auto self = shared_from_this();
        const Outgoing& next = queue_.front();
        ws_.binary(next.binary);  // the message type of the next write
        ws_.compress(!next.binary);  // binary pushes (numeric arrays, images) are never deflated
        ws_.async_write(next.buffers(), asio::bind_allocator(allocator(), [self](beast::error_code ec, std::size_t) {
            self->writing_ = false;
            self->front_in_flight_ = false;
            if (ec) {
                self->finish();
                while (!self->queue_.empty()) {  // the message whose write just ended, if finish() kept it
                    self->unqueue(self->queue_.front());
                    self->queue_.pop_front();
                }
                return;
            }
            self->unqueue(self->queue_.front());
            self->queue_.pop_front();
            self->write();
        }));
    }

    // Frames every small message waiting (up to kGatherBytes) into the layer, then writes them with one
    // non-blocking write; the rest of that write, if any, asynchronously. The messages stay counted in
    // queued() until their bytes are written.
    void write_gathered() {
        auto& layer = ws_.next_layer();
        for (;;) {
            std::size_t count = 0, bytes = 0;
            beast::error_code ec;
            while (!queue_.empty() && queue_.front().size() <= kGatherMessageMax && layer.gathered() < kGatherBytes) {
                const Outgoing& m = queue_.front();
                ws_.binary(m.binary);
                ws_.compress(!m.binary);
                ws_.write(m.buffers(), ec);  // Beast's frame, into the layer (never blocks)
                if (ec) break;
                ++count;
                bytes += m.size();
                queue_.pop_front();  // its bytes are in the layer now
            }
            if (!ec && layer.write_now(ec) && !ec) {
                release(count, bytes);
                if (queue_.empty() || closed_) return;
                if (queue_.front().size() > kGatherMessageMax || !layer.idle()) return write();
                continue;  // more than one batch was waiting
            }
            if (ec) {
                release(count, bytes);
                return fail_write();
            }
            writing_ = true;
            auto self = shared_from_this();
            layer.async_flush(asio::bind_allocator(allocator(), [self, count, bytes](beast::error_code ec) {
                self->writing_ = false;
                self->release(count, bytes);
                if (ec) return self->fail_write();
                self->write();
            }));
            return;
        }
    }

    // A write failed: the session ends, and what waits is given back.
    void fail_write() {
        finish();
        while (queue_.size() > (front_in_flight_ ? 1u : 0u)) {
            unqueue(queue_.back());
            queue_.pop_back();
        }
    }

    void release(std::size_t count, std::size_t bytes) {
        queued_count_.fetch_sub(count);
        queued_bytes_.fetch_sub(bytes);
    }

    void unqueue(const Outgoing& out) {
        queued_count_.fetch_sub(1);
        queued_bytes_.fetch_sub(out.size());
    }

    void finish() {
        if (finished_) return;
        finished_ = true;
        closed_ = true;
        // A write in flight still reads the front message: it is released when that write completes.
        while (queue_.size() > (front_in_flight_ ? 1u : 0u)) {
            unqueue(queue_.back());
            queue_.pop_back();
        }
        pacer_.cancel();
        probe_timer_.cancel();
        if (handler_->on_close) handler_->on_close(shared_from_this());
    }

    HandlerAllocator<void> allocator() const noexcept { return handler_memory_.allocator(); }

    ConnectionHandlerMemory handler_memory_;  // first member: see ConnectionHandlerMemory
    WebSocket ws_;
    std::optional<IoStrand> io_strand_;  // the socket's strand, when it is one over an io_context
    const JsonSocketHandler* handler_;
    std::size_t limit_;
    bool gather_;  // HttpOptions::websocket_gathered_writes
    std::string peer_;
    std::shared_ptr<const void> hold_;
    std::string cookie_;
    std::string target_, subprotocol_;
    beast::flat_buffer buffer_;
    std::mutex incoming_mutex_;
    std::vector<Outgoing> incoming_;  // sent, not yet taken by the strand; under incoming_mutex_
    bool wake_pending_ = false;       // under incoming_mutex_
    std::vector<Outgoing> taken_;     // the strand's: what the last wake took (its capacity is kept)
    boost::circular_buffer<Outgoing> queue_;  // front: being written while front_in_flight_; grows to limit_ + 1
    std::atomic<std::size_t> queued_count_{0}, queued_bytes_{0};
    std::atomic<std::uint64_t> dropped_{0};
    ReadPacer pacer_;
    bool writing_ = false;          // a write (Beast's asynchronous one, or a gathered batch's flush) is on its way
    bool front_in_flight_ = false;  // that write reads queue_.front() (Beast's asynchronous write)
    bool closed_ = false;
    bool finished_ = false;
    // set_liveness_probe: the strand's.
    asio::steady_timer probe_timer_;
    asio::steady_timer goodbye_timer_;  // bounds fail()'s close handshake
    std::optional<std::chrono::milliseconds> probe_timeout_;
    std::uint64_t probe_gen_ = 0;
    std::chrono::steady_clock::time_point probe_started_{}, last_receive_{};
    bool ping_in_flight_ = false;
};

/// One HTTP connection over `Stream` (Beast's TCP stream, or TlsStream for HTTPS): requests in order,
/// routes, static files, WebSocket upgrades (raw RR to the node, JSON subprotocols to their handler).
template <class Stream>
class HttpSession : public std::enable_shared_from_this<HttpSession<Stream>> {
public:
    using std::enable_shared_from_this<HttpSession<Stream>>::shared_from_this;

    HttpSession(std::shared_ptr<HttpServer> server, Stream stream)
        : server_(std::move(server)), stream_(std::move(stream)), pacer_(server_->node(), stream_.get_executor()),
          watch_timer_(stream_.get_executor()) {}

    void start(std::vector<std::byte> initial, std::shared_ptr<const void> hold = {}) {
        hold_ = std::move(hold);
        if (!initial.empty()) {
            auto b = buffer_.prepare(initial.size());
            std::memcpy(b.data(), initial.data(), initial.size());
            buffer_.commit(initial.size());
        }
        read();
    }

private:
    void read() {
        auto self = shared_from_this();
        pacer_.then([self] { self->read_now(); });
    }

    void read_now() {
        parser_.emplace();
        parser_->body_limit(server_->options().max_body_bytes);
        parser_->header_limit(16 * 1024);
        beast::get_lowest_layer(stream_).expires_after(server_->options().read_timeout);
        auto self = shared_from_this();
        bhttp::async_read(stream_, buffer_, *parser_, [self](beast::error_code ec, std::size_t n) {
            // A TLS client that closes without close_notify (most do, between requests) ends the session
            // like a plain end of stream.
            if (ec == bhttp::error::end_of_stream || ec == beast::error::timeout || ec == asio::ssl::error::stream_truncated) {
                self->shutdown();
                return;
            }
            if (ec) {
                // Malformed request or over a limit: answer 400/413 once and close.
                Request dummy;
                dummy.version(11);
                auto status = (ec == bhttp::error::body_limit || ec == bhttp::error::header_limit)
                                  ? bhttp::status::payload_too_large
                                  : bhttp::status::bad_request;
                auto r = make_response(dummy, status, ec.message() + "\n");
                r.keep_alive(false);
                self->write(std::move(r));
                return;
            }
            self->pacer_.charge(n, self->remote());
            self->on_request(self->parser_->release());
        });
    }

    void on_request(Request req) {
        head_ = req.method() == bhttp::verb::head;
        client_ = client();
        auto forwarded = [&](std::string_view name) {
            auto v = req[name];
            return std::string_view(v.data(), v.size());
        };
        if (!server_->options().trusted_proxies.empty()) {
            beast::error_code ec;
            auto ep = beast::get_lowest_layer(stream_).socket().remote_endpoint(ec);
            if (!ec)
                client_ = client_origin(ep.address(), ep.port(), forwarded("X-Forwarded-For"),
                                        forwarded("X-Forwarded-Proto"), server_->options().trusted_proxies);
        }
        // What route handlers learn about the client (kClientAddressField, kSecureField): never what it claims.
        req.erase(kClientAddressField);
        req.erase(kSecureField);
        req.set(kClientAddressField, client_.address);
        if (client_.forwarded ? client_.scheme == "https" : !std::is_same_v<Stream, beast::tcp_stream>) req.set(kSecureField, "1");
        if (server_->options().on_response) {
            request_line_.assign(req.method_string().data(), req.method_string().size());
            request_line_ += ' ';
            request_line_.append(req.target().data(), req.target().size());
        }
        const auto origin = req[bhttp::field::origin];
        if (!origin.empty() && !same_origin(origin, req[bhttp::field::host], client_.scheme) &&
            !origin_allowed(server_->options().allowed_origins, origin)) {
            auto r = make_response(req, bhttp::status::forbidden, "Forbidden Origin\n");
            r.keep_alive(false);
            write(std::move(r));
            return;
        }
        if (websocket::is_upgrade(req)) {
            upgrade(std::move(req));
            return;
        }
        std::string_view target(req.target().data(), req.target().size());
        auto path = target.substr(0, target.find('?'));
        // A route of this method, for HEAD one of GET (its headers, no body), then a route for any method.
        const WatchedRouteHandler* route = server_->find_route(req.method(), path, false);
        if (!route && head_) route = server_->find_route(bhttp::verb::get, path, false);
        if (!route) route = server_->find_route(req.method(), path);
        if (route) {
            auto self = shared_from_this();
            auto keep = std::make_shared<Request>(std::move(req));
            auto ex = stream_.get_executor();
            auto connection = std::make_shared<Watch>(self, ++request_gen_);
            (*route)(*keep, [self, keep, ex](Response r) {
                asio::post(ex, [self, r = std::move(r)]() mutable { self->write(std::move(r)); });
            }, connection);
            return;
        }
        if ((req.method() == bhttp::verb::get || req.method() == bhttp::verb::head) &&
            !server_->options().static_root.empty()) {
            serve_static(req);
            return;
        }
        write(make_response(req, bhttp::status::not_found, "Not Found\n"));
    }

    void serve_static(const Request& req) {
        std::string_view target(req.target().data(), req.target().size());
        auto path = static_path(server_->options().static_root, target);
        if (!path) {
            write(make_response(req, bhttp::status::bad_request, "Bad path\n"));
            return;
        }
        std::ifstream f(*path, std::ios::binary);
        if (!f) {
            write(make_response(req, bhttp::status::not_found, "Not Found\n"));
            return;
        }
        std::ostringstream body;
        body << f.rdbuf();
        auto r = make_response(req, bhttp::status::ok, body.str(), mime_type(*path));  // write() drops it for HEAD
        r.set(bhttp::field::cache_control, "no-cache");
        write(std::move(r));
    }

    void upgrade(Request req) {
        auto protocols = split_list(std::string_view(req[bhttp::field::sec_websocket_protocol].data(),
                                                     req[bhttp::field::sec_websocket_protocol].size()));
        std::string chosen;
        const JsonSocketHandler* json = nullptr;
        if (protocols.empty()) {
            chosen.clear();  // no list: raw RR, as CORE accepts
        } else {
            for (auto p : protocols) {
                if (iequals(p, kRRSubprotocol)) {
                    chosen = std::string(kRRSubprotocol);
                    break;
                }
                if ((json = server_->find_subprotocol(p))) {
                    chosen = std::string(p);
                    break;
                }
            }
            if (chosen.empty()) {
                std::string served = server_->subprotocol_names();
                served += (served.empty() ? "" : ", ") + std::string(kRRSubprotocol);
                auto r = make_response(req, bhttp::status::upgrade_required,
                                       "Unsupported WebSocket subprotocol; this server speaks: " + served + "\n");
                r.set(bhttp::field::sec_websocket_protocol, kRRSubprotocol);
                r.set(bhttp::field::sec_websocket_version, "13");
                r.keep_alive(false);
                write(std::move(r));
                return;
            }
        }
        // Addresses before the stream moves into the WebSocket.
        auto peer = client_.address;
        if (server_->options().on_websocket) {
            std::string line = "WebSocket " + (chosen.empty() || chosen == kRRSubprotocol ? std::string("rr") : chosen) +
                               " from " + peer;
            if (client_.forwarded)
                line += " (" + (client_.scheme.empty() ? std::string("scheme unknown") : client_.scheme) + ", via " +
                        remote() + ")";
            server_->options().on_websocket(line);
        }
        beast::error_code lec;
        auto local = beast::get_lowest_layer(stream_).socket().local_endpoint(lec);
        AcceptedStream info{lec ? std::string() : tcp_base_url(local), peer, {}, {}};
        info.web_login.assign(req[bhttp::field::cookie].data(), req[bhttp::field::cookie].size());
        info.hold = hold_;
        beast::get_lowest_layer(stream_).expires_never();
        const bool deflate =
            json && websocket_deflate_allowed(server_->options(), std::string_view(req.target().data(), req.target().size()));
        auto setup = [&chosen, deflate](auto& ws) {
            ws.set_option(websocket::stream_base::decorator([chosen](websocket::response_type& res) {
                if (!chosen.empty()) res.set(bhttp::field::sec_websocket_protocol, chosen);
            }));
            ws.read_message_max(64u * 1024u * 1024u);
            if (deflate) {
                // Negotiated only when the client offers it (the response then names the extension).
                websocket::permessage_deflate pmd;
                pmd.server_enable = true;
                pmd.msg_size_threshold = 64;  // a smaller message does not get shorter
                ws.set_option(pmd);
            }
        };
        auto server = server_;
        std::string cookie(req[bhttp::field::cookie].data(), req[bhttp::field::cookie].size());
        std::string target(req.target().data(), req.target().size());
        if (json) {
            // A JSON subprotocol: the session's writes go through the gather layer (JsonWebSocketSession).
            using Session = JsonWebSocketSession<Stream>;
            auto holder = std::make_shared<typename Session::WebSocket>(std::move(stream_));
            setup(*holder);
            holder->async_accept(req, [holder, server, json, peer, info, cookie = std::move(cookie),
                                       target = std::move(target), chosen](beast::error_code ec) {
                if (ec) return;
                const auto& o = server->options();
                auto s = std::make_shared<Session>(std::move(*holder), json, o.json_socket_queue_limit,
                                                   o.websocket_gathered_writes, peer, cookie, server->node(), target, chosen);
                s->keep(info.hold);
                s->start();
                server->track_socket(s);
            });
            return;
        }
        auto holder = std::make_shared<websocket::stream<Stream>>(std::move(stream_));
        setup(*holder);
        const bool unnamed = protocols.empty();
        holder->async_accept(req, [holder, server, info, unnamed](beast::error_code ec) {
            if (ec) return;
            if (unnamed) return sniff_unnamed(holder, server, info);
            auto node = server->node();
            if (!node) return;
            holder->binary(true);
            serve_stream(*node, WebSocketByteStream<Stream>(std::move(*holder)), info);
        });
    }

    // No subprotocol asked for: raw RR, as CORE accepts, whose first message (CreateConnection) comes
    // in binary frames. A text frame first is a JSON client that forgot its subprotocol: it gets an
    // error naming the subprotocols instead of a silent drop. The bytes read go to the node first.
    static void sniff_unnamed(std::shared_ptr<websocket::stream<Stream>> ws, std::shared_ptr<HttpServer> server,
                              AcceptedStream info) {
        auto buf = std::make_shared<std::vector<std::byte>>(4096);
        beast::get_lowest_layer(*ws).expires_after(server->options().read_timeout);
        ws->async_read_some(asio::buffer(buf->data(), buf->size()), [ws, buf, server, info](beast::error_code ec, std::size_t n) {
            if (ec) return;  // closed or timed out before a byte: nothing to serve
            beast::get_lowest_layer(*ws).expires_never();
            if (ws->got_text()) return refuse_text(ws, server->subprotocol_names());
            auto node = server->node();
            if (!node) return;
            buf->resize(n);
            ws->binary(true);
            serve_stream(*node, WebSocketByteStream<Stream>(std::move(*ws)), info, std::move(*buf));
        });
    }

    static void refuse_text(std::shared_ptr<websocket::stream<Stream>> ws, const std::string& json_protocols) {
        // Subprotocol names are HTTP tokens (no quotes or backslashes): safe inside a JSON string.
        const std::string hint = json_protocols.empty()
                                     ? std::string("this WebSocket speaks Robot Raconteur (binary frames) only")
                                     : "open the WebSocket with the subprotocol " + json_protocols + " for the JSON API";
        auto text = std::make_shared<std::string>(
            "{\"error\": {\"name\": \"RobotRaconteur.ProtocolError\", \"message\": \"no WebSocket subprotocol was "
            "asked for, so this connection speaks raw Robot Raconteur (subprotocol " +
            std::string(kRRSubprotocol) + "); " + hint + "\"}}");
        ws->text(true);
        beast::get_lowest_layer(*ws).expires_after(std::chrono::seconds(5));  // the write and the close handshake
        ws->async_write(asio::buffer(*text), [ws, text, hint](beast::error_code ec, std::size_t) {
            if (ec) return;
            // A close frame's reason has at most 123 bytes.
            websocket::close_reason reason(websocket::close_code::policy_error, beast::string_view(hint).substr(0, 123));
            ws->async_close(reason, [ws](beast::error_code) {});
        });
    }

    // --- the connection of a request being answered (RequestConnection) ---

    class Watch : public RequestConnection {
    public:
        Watch(std::weak_ptr<HttpSession> session, std::uint64_t gen) : session_(std::move(session)), gen_(gen) {}
        void on_gone(std::function<void()> gone) override {
            auto s = session_.lock();
            if (!s) return;
            asio::post(s->stream_.get_executor(), [s, gen = gen_, gone = std::move(gone)]() mutable {
                s->arm_watch(gen, std::move(gone));
            });
        }

    private:
        std::weak_ptr<HttpSession> session_;
        std::uint64_t gen_;
    };

    // On the strand. Nothing else waits on the socket while a request is handled: a readable socket
    // with nothing to read is the client's end (FIN or RST).
    void arm_watch(std::uint64_t gen, std::function<void()> gone) {
        if (gen != request_gen_) return;  // answered already
        gone_ = std::move(gone);
        if (watching_) return;
        watching_ = true;
        auto self = shared_from_this();
        beast::get_lowest_layer(stream_).socket().async_wait(tcp::socket::wait_read, [self, gen](beast::error_code ec) {
            if (gen != self->request_gen_ || ec == asio::error::operation_aborted) return;
            beast::error_code aec;
            const std::size_t n = beast::get_lowest_layer(self->stream_).socket().available(aec);
            if (ec || aec || n == 0) return self->client_gone(gen);
            self->poll_gone(gen);  // bytes wait (a pipelined request, a TLS alert): the TCP state tells
        });
    }

    void poll_gone(std::uint64_t gen) {
        watch_timer_.expires_after(std::chrono::milliseconds(100));
        auto self = shared_from_this();
        watch_timer_.async_wait([self, gen](beast::error_code ec) {
            if (ec || gen != self->request_gen_) return;
            if (self->peer_closed()) return self->client_gone(gen);
            self->poll_gone(gen);
        });
    }

    bool peer_closed() {
        auto& socket = beast::get_lowest_layer(stream_).socket();
        tcp_info info{};
        socklen_t len = sizeof info;
        if (::getsockopt(socket.native_handle(), IPPROTO_TCP, TCP_INFO, &info, &len) != 0) return true;
        return info.tcpi_state != TCP_ESTABLISHED;
    }

    void client_gone(std::uint64_t gen) {
        if (gen != request_gen_) return;
        watching_ = false;
        auto gone = std::move(gone_);
        gone_ = nullptr;
        if (gone) gone();
    }

    // The request is answered: its watch ends (the socket's wait cancelled before the write starts).
    void end_watch() {
        ++request_gen_;
        gone_ = nullptr;
        if (!watching_) return;
        watching_ = false;
        beast::error_code ec;
        beast::get_lowest_layer(stream_).socket().cancel(ec);
        watch_timer_.cancel();
    }

    ClientOrigin client() const { return ClientOrigin{remote(), "", false}; }

    std::string remote() const {
        beast::error_code ec;
        auto ep = beast::get_lowest_layer(stream_).socket().remote_endpoint(ec);
        return ec ? std::string("?") : ep.address().to_string() + ":" + std::to_string(ep.port());
    }

    void write(Response r) {
        end_watch();
        if (const auto& hook = server_->options().on_response) {
            // The client as the request named it (behind a trusted proxy: the proxy's client).
            hook(request_line_.empty() || client_.address.empty() ? remote() : client_.address, request_line_, r.result_int());
            request_line_.clear();
        }
        auto self = shared_from_this();
        auto res = std::make_shared<Response>(std::move(r));
        res->prepare_payload();
        if (head_) {  // the answer to HEAD: GET's Content-Length, no body
            res->body().clear();
            head_ = false;
        }
        bhttp::async_write(stream_, *res, [self, res](beast::error_code ec, std::size_t) {
            if (ec || !res->keep_alive()) {
                self->shutdown();
                return;
            }
            self->read();
        });
    }

    void shutdown() {
        beast::error_code ec;
        auto& socket = beast::get_lowest_layer(stream_).socket();
        socket.shutdown(tcp::socket::shutdown_send, ec);
        socket.close(ec);
    }

    std::shared_ptr<HttpServer> server_;
    Stream stream_;
    std::shared_ptr<const void> hold_;  // the connection's per-address slot (AcceptedStream::hold)
    beast::flat_buffer buffer_;
    std::optional<bhttp::request_parser<bhttp::string_body>> parser_;
    bool head_ = false;  // the request being answered is HEAD (one at a time: read, answer, read)
    ClientOrigin client_;  // who sent the request being answered (behind a trusted proxy: the proxy's client)
    std::string request_line_;  // "METHOD target" of that request, for HttpOptions::on_response
    ReadPacer pacer_;  // gateway.limits rates: requests and their bytes
    // RequestConnection of the request being answered: its number, its `gone`, the wait on the socket.
    std::uint64_t request_gen_ = 0;
    std::function<void()> gone_;
    bool watching_ = false;
    asio::steady_timer watch_timer_;
};

}  // namespace rr::server::http::detail
