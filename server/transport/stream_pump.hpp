// Moves bytes and time between one Asio stream and one ConnectionLogic; never interprets them.
// All work for a connection runs on the pump's strand; other threads reach the logic only through
// post(). Reads are bounded by the logic's limits (it rejects oversized messages before buffering).
#pragma once

#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <type_traits>
#include <variant>

#include <boost/asio/basic_stream_socket.hpp>
#include <boost/asio/bind_executor.hpp>
#include <boost/asio/socket_base.hpp>
#include <boost/asio/bind_allocator.hpp>
#include <boost/asio/dispatch.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>
#include <boost/asio/write.hpp>

#include "server/common/caller_runs_executor.hpp"
#include "server/common/handler_memory.hpp"
#include "server/common/read_throttle.hpp"
#include "server/transport/connection_logic.hpp"

namespace rr::server {

namespace asio = boost::asio;

/// A plain socket (TCP, Unix): the pump writes to it directly from its strand, without an
/// asynchronous write's completion round trip through the io_context (a post and, with several
/// worker threads, a wake-up per message). TLS and WebSocket streams keep asynchronous writes.
template <class Stream>
concept DirectWriteSocket = requires(Stream& s, boost::system::error_code& ec) {
    typename Stream::protocol_type;
    requires std::is_base_of_v<asio::basic_stream_socket<typename Stream::protocol_type, typename Stream::executor_type>,
                               Stream>;
};

/// Type-erased handle a ConnectionLogic owner uses to run code on the connection's strand.
class PumpHandle {
public:
    virtual ~PumpHandle() = default;
    /// Runs `fn` on the strand, then flushes output and re-arms the timer. Once the pump has closed,
    /// `fn` is destroyed unrun: a completion it carries must answer from its destructor
    /// (server/transport/completion_guard.hpp), or its caller waits for nothing.
    virtual void post(std::function<void()> fn) = 0;
    /// Like post(), but runs `fn` at once when already on the strand.
    virtual void dispatch(std::function<void()> fn) = 0;
    /// Calls the logic's on_wake() on the strand (at once when already on it), then flushes: the
    /// hand-off from another thread (a fan-out's wire value or event, a worker's reply, a gateway's
    /// forwarded request) without a std::function, its operation in the pump's own HandlerMemory.
    /// The caller keeps what it hands over and wakes once until on_wake() takes it; once the pump has
    /// closed, the wake is dropped (what waits must then be answered by on_transport_closed()).
    virtual void wake() = 0;
    /// True when the calling thread is known not to be running the pump's strand (a wake from it
    /// cannot run at once). False on the strand, and when the strand cannot tell.
    virtual bool known_off_strand() const { return false; }
    /// Closes the transport after flushing what is pending; reads nothing more meanwhile.
    virtual void close() = 0;
    /// close() because the node is stopping: a transport that can say so tells its peer (a WebSocket's
    /// close frame 1001 Going Away, so a client can tell a restart from a network failure).
    virtual void close_going_away() { close(); }
    /// Closes the transport at once, unflushed, and reports it to the logic. Only for a caller that
    /// knows no thread runs the pump's executor: a node whose threads have stopped before a close()
    /// could finish (a peer still flooding it, a loaded machine), so that its peer sees the end.
    virtual void close_now() {}
};

template <class Stream>
class StreamPump : public PumpHandle, public std::enable_shared_from_this<StreamPump<Stream>> {
public:
    /// An executor that serialises work: a strand, type-erased (Beast needs the erased form to track work).
    using Strand = asio::any_io_executor;
    /// The strand connection_strand() makes over an io_context's own executor.
    using IoStrand = asio::strand<asio::io_context::executor_type>;
    /// The strand a client connection makes over a CallerRunsExecutor (server/client/client.hpp).
    using CallerRunsStrand = asio::strand<CallerRunsExecutor>;
    /// The strand reads complete on: strand_ itself, or its concrete strand when it is one of these.
    /// Beast's streams need the legacy executor interface a CallerRunsExecutor lacks: only plain
    /// sockets read through the concrete CallerRunsStrand.
    using ReadStrand = std::conditional_t<DirectWriteSocket<Stream>, std::variant<Strand, IoStrand, CallerRunsStrand>,
                                          std::variant<Strand, IoStrand>>;

    StreamPump(Stream stream, Strand strand, std::shared_ptr<ConnectionLogic> logic)
        : stream_(std::move(stream)), strand_(std::move(strand)), timer_(strand_), logic_(std::move(logic)) {
        if (const auto* io = strand_.template target<IoStrand>()) read_strand_ = *io;
        if constexpr (DirectWriteSocket<Stream>)
            if (const auto* caller_runs = strand_.template target<CallerRunsStrand>()) read_strand_ = *caller_runs;
    }

    ~StreamPump() {
        if (!transport_reported_ && logic_) logic_->on_abandoned();
    }

    /// Keeps `hold` alive until the pump is destroyed (the connection's per-address slot).
    void keep(std::shared_ptr<const void> hold) { hold_ = std::move(hold); }

    /// Paces reads with `throttle` (before start()): after each read the pump pauses reading for as
    /// long as the throttle says, calling `on_pause` when a pause begins.
    void throttle(std::unique_ptr<ReadThrottle> throttle, std::function<void()> on_pause) {
        throttle_ = std::move(throttle);
        on_pause_ = std::move(on_pause);
        throttle_timer_.emplace(strand_);
    }

    /// Starts reading; `initial` bytes (already read while detecting the protocol) are fed first.
    void start(std::span<const std::byte> initial = {}) {
        if constexpr (DirectWriteSocket<Stream>) {
            // Synchronous writes must not block the strand: a full socket buffer returns would_block
            // and the rest goes out asynchronously.
            boost::system::error_code ec;
            stream_.non_blocking(true, ec);
            direct_write_ = !ec;
        }
        auto self = this->shared_from_this();
        std::vector<std::byte> first(initial.begin(), initial.end());
        asio::dispatch(strand_, [self, first = std::move(first)] {
            if (!first.empty()) {
                self->logic_->on_bytes(first, mono_now());
                if (self->throttle_) self->pace(first);  // the framing count starts at the stream's first byte
            }
            self->read();
            self->after_work();
        });
    }

    // post, dispatch and wake go through the concrete strand when there is one, with their operation
    // in the pump's own memory: they come from other threads (a worker's reply, a blocking caller that
    // is not an I/O thread at all), where Asio's per-thread cache has nothing to give.
    void post(std::function<void()> fn) override {
        to_strand(/*may_run_here=*/false, [self = this->shared_from_this(), fn = std::move(fn)] {
            if (self->closed_) return;
            fn();
            self->after_work();
        });
    }

    void dispatch(std::function<void()> fn) override {
        to_strand(/*may_run_here=*/true, [self = this->shared_from_this(), fn = std::move(fn)] {
            if (self->closed_) return;
            fn();
            self->after_work();
        });
    }

    void wake() override {
        to_strand(/*may_run_here=*/true, [self = this->shared_from_this()] {
            if (self->closed_) return;
            self->logic_->on_wake();
            self->after_work();
        });
    }

    bool known_off_strand() const override {
        return std::visit(
            [](const auto& strand) {
                if constexpr (std::is_same_v<std::decay_t<decltype(strand)>, Strand>)
                    return false;  // type-erased: cannot tell
                else
                    return !strand.running_in_this_thread();
            },
            read_strand_);
    }

    void close() override {
        auto self = this->shared_from_this();
        asio::post(strand_, [self] {
            self->close_requested_ = true;
            self->after_work();
        });
    }

    void close_going_away() override {
        auto self = this->shared_from_this();
        asio::post(strand_, [self] {
            self->going_away_ = true;
            self->close_requested_ = true;
            self->after_work();
        });
    }

    void close_now() override {
        shutdown();
        // A close handshake still waiting for the peer's answer (no thread runs it any more) ends here.
        if (goodbye_pending_) {
            goodbye_pending_ = false;
            boost::system::error_code ignored;
            if constexpr (requires(Stream& s) { s.lowest_layer(); })
                stream_.lowest_layer().close(ignored);
            else
                stream_.close(ignored);
        }
    }

    Stream& stream() { return stream_; }
    const Strand& strand() const { return strand_; }

private:
    void read() {
        // Once close() is asked for, nothing more is read: a peer that keeps sending (a flood of
        // requests) must not keep the connection from draining and closing before its node stops.
        if (reading_ || throttled_ || close_requested_) return;
        if (!logic_->wants_read()) {
            read_paused_ = true;  // resumed by after_work() once the output has drained
            return;
        }
        read_paused_ = false;
        reading_ = true;
        // The rest of a large message goes straight into its final buffer; everything else through ours.
        std::span<std::byte> into = logic_->read_space();
        if (into.empty()) into = buffer_;
        auto on_read = [self = this->shared_from_this(), at = into.data()](boost::system::error_code ec, std::size_t n) {
            self->reading_ = false;
            if (self->closed_) return;
            if (ec) {
                self->transport_failed(ec);
                return;
            }
            const std::span<const std::byte> got(at, n);
            // Paced first: bytes read in place may be released by on_bytes (a completed message).
            if (self->throttle_) self->pace(got);
            self->logic_->on_bytes(got, mono_now());
            self->after_work();
            if (!self->closed_ && !self->logic_->wants_close()) self->read();
        };
        // One completion per message: bound to the concrete strand when there is one, Asio dispatches
        // it without the type-erased executor's copies and indirect calls (issue 14, bench/profile.sh).
        std::visit(
            [&](const auto& strand) {
                stream_.async_read_some(asio::buffer(into.data(), into.size()),
                                        asio::bind_executor(strand, std::move(on_read)));
            },
            read_strand_);
    }

    // Charges the bytes just read to the throttle; over the rate, reads pause (TCP back-pressure) until
    // the throttle's wait has passed.
    void pace(std::span<const std::byte> got) {
        const auto wait = throttle_->charge(got, ReadThrottle::Clock::now());
        if (wait <= std::chrono::nanoseconds{0}) return;
        throttled_ = true;
        if (on_pause_) on_pause_();
        throttle_timer_->expires_after(wait);
        auto self = this->shared_from_this();
        throttle_timer_->async_wait(asio::bind_executor(strand_, [self](boost::system::error_code ec) {
            self->throttled_ = false;
            if (ec || self->closed_ || self->logic_->wants_close()) return;
            self->read();
        }));
    }

    void after_work() {
        if (closed_) return;
        flush();
        if (closed_) return;
        arm_timer();
        if (read_paused_ && !closed_ && logic_->wants_read() && !logic_->wants_close()) read();
    }

    void flush() {
        if (writing_ || closed_) return;
        if (!logic_->has_output()) {
            if (logic_->wants_close() || close_requested_) shutdown();
            return;
        }
        logic_->take_output(write_buffer_);
        if (write_buffer_.splices().empty()) {
            const auto& owned = write_buffer_.owned();
            write_out(asio::const_buffer(owned.data(), owned.size()));
            return;
        }
        // Large payloads shared with other sessions or the received frame: one gathered write.
        pieces_.clear();
        write_buffer_.for_each_piece(
            [this](std::span<const std::byte> piece) { pieces_.emplace_back(piece.data(), piece.size()); });
        write_out(std::span<asio::const_buffer>(pieces_));
    }

    // Writes `buffers` (views of write_buffer_), directly from the strand when the socket allows, the
    // rest asynchronously; write_buffer_ is cleared once all of it is written.
    template <class Buffers>
    void write_out(Buffers buffers) {
        if constexpr (DirectWriteSocket<Stream>) {
            if (direct_write_) {
                boost::system::error_code ec;
                std::size_t written = stream_.write_some(buffers, ec);
                if (ec == asio::error::would_block || ec == asio::error::try_again) {
                    written = 0;
                } else if (ec) {
                    write_buffer_.clear();
                    transport_failed(ec);
                    return;
                }
                if (written == asio::buffer_size(buffers)) {
                    write_buffer_.clear();
                    return;
                }
                buffers = skip(buffers, written);
            }
        }
        writing_ = true;
        auto self = this->shared_from_this();
        asio::async_write(stream_, buffers,
                          asio::bind_allocator(allocator(), asio::bind_executor(strand_, [self](boost::system::error_code ec, std::size_t) {
                              self->writing_ = false;
                              self->write_buffer_.clear();
                              if (self->closed_) return;
                              if (ec) {
                                  self->transport_failed(ec);
                                  return;
                              }
                              self->after_work();
                          })));
    }

    static asio::const_buffer skip(asio::const_buffer buffer, std::size_t n) { return buffer + n; }
    static std::span<asio::const_buffer> skip(std::span<asio::const_buffer> pieces, std::size_t n) {
        while (!pieces.empty() && n >= pieces.front().size()) {
            n -= pieces.front().size();
            pieces = pieces.subspan(1);
        }
        if (n > 0) pieces.front() += n;
        return pieces;
    }

    void arm_timer() {
        auto deadline = logic_->next_deadline();
        if (!deadline) {
            timer_.cancel();
            timer_armed_ = false;
            return;
        }
        // A later deadline (every message moves the heartbeat and receive deadlines) keeps the armed
        // wait: it fires early, on_timer() finds nothing due and the timer is re-armed then. Re-arming
        // per message cost a timerfd_settime and a cancelled completion (bench/profile.sh).
        if (timer_armed_ && *deadline >= armed_for_) return;
        timer_armed_ = true;
        armed_for_ = *deadline;
        timer_.expires_at(*deadline);
        auto self = this->shared_from_this();
        timer_.async_wait(asio::bind_executor(strand_, [self, when = *deadline](boost::system::error_code ec) {
            if (ec || self->closed_ || when != self->armed_for_) return;
            self->timer_armed_ = false;
            self->logic_->on_timer(mono_now());
            self->after_work();
        }));
    }

    void transport_failed(boost::system::error_code ec) {
        if (closed_) return;
        transport_reported_ = true;
        logic_->on_transport_closed(make_error(MessageErrorType::ConnectionError,
                                               ec == asio::error::eof ? "connection closed by peer" : ec.message()));
        shutdown();
    }

    void shutdown() {
        if (closed_) return;
        closed_ = true;
        timer_.cancel();
        if (throttle_timer_) throttle_timer_->cancel();
        boost::system::error_code ignored;
        // The node stopping ends a WebSocket with a close frame 1001 Going Away rather than a bare TCP
        // close, which a client reports as 1006 (abnormal: a crash, a cut network). The handshake is
        // bounded; the socket closes when it ends (or at close_now()).
        if constexpr (requires(Stream& s) { s.async_goodbye(true, [](boost::system::error_code) {}); }) {
            if (going_away_) {
                goodbye_pending_ = true;
                auto self = this->shared_from_this();
                stream_.async_goodbye(going_away_, asio::bind_executor(strand_, [self](boost::system::error_code) {
                    self->goodbye_pending_ = false;
                }));
                if (!transport_reported_) {
                    transport_reported_ = true;
                    logic_->on_transport_closed(make_error(MessageErrorType::ConnectionError, "connection closed"));
                }
                return;
            }
        }
        if constexpr (requires(Stream& s) { s.lowest_layer(); }) {
            stream_.lowest_layer().shutdown(asio::socket_base::shutdown_both, ignored);
            stream_.lowest_layer().close(ignored);
        } else {
            stream_.close(ignored);
        }
        if (!transport_reported_) {
            transport_reported_ = true;
            logic_->on_transport_closed(make_error(MessageErrorType::ConnectionError, "connection closed"));
        }
    }

    // Runs `work` on the read strand (dispatch when `may_run_here`, else post), its operation in the
    // pump's memory.
    template <class Work>
    void to_strand(bool may_run_here, Work&& work) {
        std::visit(
            [&](const auto& strand) {
                auto bound = asio::bind_allocator(allocator(), std::forward<Work>(work));
                if (may_run_here)
                    asio::dispatch(strand, std::move(bound));
                else
                    asio::post(strand, std::move(bound));
            },
            read_strand_);
    }

    // For the operations other threads make or complete: post, dispatch, the wake, the asynchronous write. A read is
    // made and completed on the strand's threads, where Asio's per-thread cache serves it (the
    // service's Nop measured 131 instructions more with reads in the HandlerMemory).
    HandlerAllocator<void> allocator() const noexcept { return handler_memory_.allocator(); }

    ConnectionHandlerMemory handler_memory_;  // first member: see ConnectionHandlerMemory
    Stream stream_;
    Strand strand_;
    ReadStrand read_strand_{strand_};
    asio::steady_timer timer_;
    std::shared_ptr<ConnectionLogic> logic_;
    std::shared_ptr<const void> hold_;
    std::unique_ptr<ReadThrottle> throttle_;
    std::function<void()> on_pause_;
    std::optional<asio::steady_timer> throttle_timer_;
    bool throttled_ = false;
    std::array<std::byte, 64 * 1024> buffer_{};
    GatherBuffer write_buffer_;
    std::vector<asio::const_buffer> pieces_;  // write_buffer_'s pieces for a gathered write
    bool writing_ = false;
    bool direct_write_ = false;
    bool reading_ = false;
    bool read_paused_ = false;
    bool closed_ = false;
    bool close_requested_ = false;
    bool going_away_ = false;       // close_going_away(): the node is stopping
    bool goodbye_pending_ = false;  // a WebSocket close handshake is under way (shutdown())
    bool timer_armed_ = false;
    bool transport_reported_ = false;
    MonoTime armed_for_{};
};

}  // namespace rr::server
