// GatherStream: a stream layer under Beast's `websocket::stream` that lets a session write every
// message waiting for one client with one kernel write (issue 56: gathered writes for the fan-out).
//
// Beast writes each WebSocket frame with a write on the layer below it. Here:
//   * a synchronous `write_some` (what `websocket::stream::write` calls) never blocks: it copies the
//     bytes into the layer's gather buffer and returns them all as written. A session serialises
//     several messages this way, each as Beast frames it (header, deflate, no frame code of ours),
//     then calls `write_now` (one non-blocking write of everything gathered, on a TCP stream) and,
//     when the kernel did not take it all, `async_flush` (the rest with asynchronous writes);
//   * an asynchronous `async_write_some` (Beast's own operations: the handshake, pongs, pings, the
//     close frame, and messages a session writes asynchronously) goes straight to the layer below
//     when nothing is gathered or being written, without a copy; otherwise its bytes are copied
//     behind what is gathered and it completes once they are written, so every byte leaves in the
//     order it was written to this layer (a close frame after the messages gathered before it);
//   * reads, and the WebSocket teardown, go to the layer below unchanged.
//
// Limits: the gather buffer holds what one session gathered between two flushes. A synchronous write
// that brings it to `max_gathered` bytes or more starts the write of it at once (the caller should stop
// gathering then: full()); no write is refused for size, so the buffer is bounded by what the caller
// gathers before it sees full() (the JSON session: full() plus one message of at most its gather size).
//
// Errors: the first error of a write on the layer below is kept; it is given once to each operation
// waiting for bytes (the flush, an asynchronous write queued behind), what was gathered is dropped,
// and every later write (synchronous, asynchronous, write_now, async_flush) fails with it at once.
//
// Thread safety: none; every call on the stream's strand, as for the websocket::stream above it.
// Completion handlers are never called from inside the call that started them (posted when the
// operation completes at once), and otherwise from the completion of the layer below's write.
// Lifetime: operations in flight keep the layer's state (not the layer) alive; a layer destroyed with
// a write in flight only makes that write's waiters complete with its result.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <list>
#include <memory>
#include <type_traits>
#include <utility>

#include <boost/asio/any_completion_handler.hpp>
#include <boost/asio/append.hpp>
#include <boost/asio/associated_executor.hpp>
#include <boost/asio/async_result.hpp>
#include <boost/asio/buffer.hpp>
#include <boost/asio/dispatch.hpp>
#include <boost/asio/error.hpp>
#include <boost/asio/post.hpp>
#include <boost/beast/core/basic_stream.hpp>
#include <boost/beast/core/flat_buffer.hpp>
#include <boost/beast/core/stream_traits.hpp>
#include <boost/beast/websocket/teardown.hpp>

namespace rr::server::http {

namespace gather_detail {
template <class T>
struct is_basic_stream : std::false_type {};
template <class Protocol, class Executor, class RatePolicy>
struct is_basic_stream<boost::beast::basic_stream<Protocol, Executor, RatePolicy>> : std::true_type {};
}  // namespace gather_detail

template <class NextLayer>
class GatherStream {
public:
    using next_layer_type = NextLayer;
    using executor_type = boost::beast::executor_type<NextLayer>;
    using error_code = boost::system::error_code;

    /// Default bound of the gather buffer (max_gathered), bytes.
    static constexpr std::size_t kDefaultMaxGathered = 64 * 1024;

    template <class... Args>
    explicit GatherStream(Args&&... args) : next_(std::forward<Args>(args)...), s_(std::make_shared<State>()) {
        s_->next = &next_;
    }
    GatherStream(GatherStream&& other) noexcept : next_(std::move(other.next_)), s_(std::move(other.s_)) {
        if (s_) s_->next = &next_;
    }
    GatherStream& operator=(GatherStream&&) = delete;
    ~GatherStream() {
        if (s_) s_->next = nullptr;
    }

    executor_type get_executor() noexcept { return next_.get_executor(); }
    NextLayer& next_layer() noexcept { return next_; }
    const NextLayer& next_layer() const noexcept { return next_; }

    // --- gathering ---

    /// Bytes waiting in the gather buffer (not yet handed to the layer below).
    std::size_t gathered() const noexcept { return s_->gathered.size(); }
    /// Whether a caller that gathers should stop and flush: the buffer reached max_gathered().
    bool full() const noexcept { return s_->gathered.size() >= s_->max_gathered; }
    std::size_t max_gathered() const noexcept { return s_->max_gathered; }
    void max_gathered(std::size_t bytes) noexcept { s_->max_gathered = bytes; }
    /// Nothing gathered, nothing being written, no error: a synchronous write now is the next thing
    /// on the wire after everything written before.
    bool idle() const noexcept { return !s_->in_flight && s_->gathered.size() == 0 && !s_->error; }
    /// The error that ended writing, if any.
    error_code error() const noexcept { return s_->error; }
    /// Writes handed to the layer below (each non-blocking write and each asynchronous write_some),
    /// since construction. Readable from any thread (diagnostics, tests).
    std::uint64_t writes() const noexcept { return s_->writes.load(std::memory_order_relaxed); }

    /// Hands what is gathered to the kernel now when the layer below is a TCP stream and nothing is
    /// being written: one non-blocking write. Returns true when nothing is left to write (all taken,
    /// or nothing gathered) or on an error (in `ec`, kept: see Errors); false when bytes remain, which
    /// async_flush() then writes. Never blocks.
    bool write_now(error_code& ec) {
        ec = {};
        State& s = *s_;
        if (s.error) {
            ec = s.error;
            return true;
        }
        if (s.in_flight) return false;
        if (s.gathered.size() == 0) return true;
        if constexpr (gather_detail::is_basic_stream<NextLayer>::value) {
            auto& socket = next_.socket();
            if (!socket.non_blocking()) {
                socket.non_blocking(true, ec);
                if (ec) {
                    s.fail(ec);
                    return true;
                }
            }
            s.writes.fetch_add(1, std::memory_order_relaxed);
            const std::size_t n = socket.write_some(s.gathered.data(), ec);
            if (ec == boost::asio::error::would_block || ec == boost::asio::error::try_again) {
                ec = {};
                return false;
            }
            if (ec) {
                s.fail(ec);
                return true;
            }
            s.gathered.consume(n);
            s.written += n;
            return s.gathered.size() == 0;
        } else {
            return false;
        }
    }

    /// Completes (`void(error_code)`) once every byte gathered so far has been handed to the layer
    /// below, or with the error that ended writing. Starts the write when none is in flight.
    template <class Token>
    auto async_flush(Token&& token) {
        return boost::asio::async_initiate<Token, void(error_code)>(
            [this](auto handler) {
                State& s = *s_;
                if (s.error || (s.gathered.size() == 0 && s.sending.size() == 0)) {
                    auto ex = boost::asio::get_associated_executor(handler, get_executor());
                    boost::asio::post(ex, boost::asio::append(std::move(handler), s.error));
                    return;
                }
                s.waiters.push_back(Waiter{s.accepted, 0, true,
                                           FlushHandler(std::move(handler)), WriteHandler()});
                if (!s.in_flight) State::start_write(s_);
            },
            token);
    }

    // --- AsyncStream / SyncStream ---

    template <class MutableBuffers, class Token>
    auto async_read_some(const MutableBuffers& buffers, Token&& token) {
        return next_.async_read_some(buffers, std::forward<Token>(token));
    }
    template <class MutableBuffers>
    std::size_t read_some(const MutableBuffers& buffers) {
        return next_.read_some(buffers);
    }
    template <class MutableBuffers>
    std::size_t read_some(const MutableBuffers& buffers, error_code& ec) {
        return next_.read_some(buffers, ec);
    }

    /// Gathers `buffers` (copied); returns their size. Never blocks. Fails with the kept error.
    template <class ConstBuffers>
    std::size_t write_some(const ConstBuffers& buffers, error_code& ec) {
        ec = {};
        State& s = *s_;
        if (s.error) {
            ec = s.error;
            return 0;
        }
        const std::size_t n = s.append(buffers);
        if (s.gathered.size() >= s.max_gathered && !s.in_flight) State::start_write(s_);
        return n;
    }
    template <class ConstBuffers>
    std::size_t write_some(const ConstBuffers& buffers) {
        error_code ec;
        const std::size_t n = write_some(buffers, ec);
        if (ec) boost::throw_exception(boost::system::system_error(ec));
        return n;
    }

    /// Straight to the layer below when idle (no copy); else copied behind what is gathered, and
    /// completed with all its bytes once they are written.
    template <class ConstBuffers, class Token>
    auto async_write_some(const ConstBuffers& buffers, Token&& token) {
        return boost::asio::async_initiate<Token, void(error_code, std::size_t)>(
            [this](auto handler, const ConstBuffers& b) {
                State& s = *s_;
                if (s.error) {
                    auto ex = boost::asio::get_associated_executor(handler, get_executor());
                    boost::asio::post(ex, boost::asio::append(std::move(handler), s.error, std::size_t{0}));
                    return;
                }
                if (!s.in_flight && s.gathered.size() == 0 && s.sending.size() == 0) {
                    s.in_flight = true;
                    s.writes.fetch_add(1, std::memory_order_relaxed);
                    auto ex = boost::asio::get_associated_executor(handler, get_executor());
                    next_.async_write_some(
                        b, boost::asio::bind_executor(ex, [st = s_, h = std::move(handler)](error_code ec, std::size_t n) mutable {
                            st->in_flight = false;
                            if (ec && !st->error) st->fail(ec);
                            // Bytes gathered meanwhile (behind this write) go now; after an error their
                            // waiters get it.
                            if (!st->error && st->gathered.size() > 0 && st->next) State::start_write(st);
                            State::settle(st);
                            std::move(h)(ec, n);
                        }));
                    return;
                }
                const std::size_t n = s.append(b);
                s.waiters.push_back(Waiter{s.accepted, n, false, FlushHandler(), WriteHandler(std::move(handler))});
                if (!s.in_flight) State::start_write(s_);
            },
            token, buffers);
    }

private:
    using FlushHandler = boost::asio::any_completion_handler<void(error_code)>;
    using WriteHandler = boost::asio::any_completion_handler<void(error_code, std::size_t)>;

    /// An operation waiting for the bytes up to `end` (a count over everything gathered) to be written.
    struct Waiter {
        std::uint64_t end;
        std::size_t bytes;  // a write's own size
        bool flush;
        FlushHandler on_flushed;
        WriteHandler on_written;
    };

    struct State {
        NextLayer* next = nullptr;  // null once the layer is gone
        boost::beast::flat_buffer gathered;  // written to by write_some/async_write_some
        boost::beast::flat_buffer sending;   // being written (only the write in flight touches it)
        std::uint64_t accepted = 0, written = 0;  // bytes ever gathered / handed to the layer below from them
        bool in_flight = false;
        error_code error;
        // By `end`; one or two (Beast writes one frame at a time). A list: Asio 1.81's any_completion_handler
        // must not be move-assigned (its move assignment wraps the handler in another), as erasing from a
        // vector would.
        std::list<Waiter> waiters;
        std::size_t max_gathered = kDefaultMaxGathered;
        std::atomic<std::uint64_t> writes{0};

        template <class ConstBuffers>
        std::size_t append(const ConstBuffers& buffers) {
            const std::size_t n = boost::asio::buffer_size(buffers);
            auto space = gathered.prepare(n);
            boost::asio::buffer_copy(space, buffers);
            gathered.commit(n);
            accepted += n;
            return n;
        }

        void fail(error_code ec) {
            error = ec;
            gathered.clear();
            // `sending` may still be read by a write in flight: it is cleared when that write ends.
        }

        // Writes `sending` (refilled from `gathered` when empty) with asynchronous writes on the layer
        // below, one at a time, until both are empty; completes the waiters as their bytes go.
        static void start_write(const std::shared_ptr<State>& self) {
            State& s = *self;
            if (s.sending.size() == 0) std::swap(s.sending, s.gathered);
            if (s.sending.size() == 0 || !s.next) return;
            s.in_flight = true;
            s.writes.fetch_add(1, std::memory_order_relaxed);
            s.next->async_write_some(s.sending.data(), [self](error_code ec, std::size_t n) { on_written(self, ec, n); });
        }

        static void on_written(const std::shared_ptr<State>& self, error_code ec, std::size_t n) {
            State& s = *self;
            s.in_flight = false;
            if (!ec && !s.next) ec = boost::asio::error::operation_aborted;
            if (ec) {
                if (!s.error) s.fail(ec);
                s.sending.clear();
            } else {
                s.sending.consume(n);
                s.written += n;
                if (s.sending.size() > 0 || s.gathered.size() > 0) start_write(self);
            }
            settle(self);
        }

        // Completes the waiters whose bytes are written (all of them after an error). The state is
        // consistent before any waiter runs (a waiter may write again).
        static void settle(const std::shared_ptr<State>& self) {
            State& s = *self;
            while (!s.waiters.empty() && (s.error || s.waiters.front().end <= s.written)) {
                Waiter w = std::move(s.waiters.front());
                s.waiters.pop_front();
                if (w.flush) {
                    auto ex = boost::asio::get_associated_executor(w.on_flushed);
                    boost::asio::dispatch(ex, boost::asio::append(std::move(w.on_flushed), s.error));
                } else {
                    const std::size_t n = s.error ? 0 : w.bytes;
                    auto ex = boost::asio::get_associated_executor(w.on_written);
                    boost::asio::dispatch(ex, boost::asio::append(std::move(w.on_written), s.error, n));
                }
            }
        }
    };

    NextLayer next_;
    std::shared_ptr<State> s_;
};

/// The WebSocket teardown of the layer below (Beast finds these by argument-dependent lookup).
template <class NextLayer>
void teardown(boost::beast::role_type role, GatherStream<NextLayer>& stream, boost::system::error_code& ec) {
    using boost::beast::websocket::teardown;
    teardown(role, stream.next_layer(), ec);
}

template <class NextLayer, class TeardownHandler>
void async_teardown(boost::beast::role_type role, GatherStream<NextLayer>& stream, TeardownHandler&& handler) {
    using boost::beast::websocket::async_teardown;
    async_teardown(role, stream.next_layer(), std::forward<TeardownHandler>(handler));
}

}  // namespace rr::server::http
