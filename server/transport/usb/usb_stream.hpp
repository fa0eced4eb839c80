// One RR stream of an rr+usb link as an Asio byte stream (async_read_some, async_write_some,
// get_executor, close), so StreamPump carries RR messages over it exactly as over TCP (wire.md §6).
// Used on both ends: the host's link (usb_host_link.hpp) and a device emulator serving the stream
// with server::serve_stream (transport.hpp).
//
// The stream is a handle (stream id + the channel that owns the link); the channel runs the
// operations on its own serialisation (a strand or a mutex) and completes them by invoking the
// StreamCompletion, which posts the user's handler to its associated executor (the pump's strand).
// Errors: boost::asio::error::eof when the peer closed the stream, operation_aborted after close(),
// usb_errc codes (usb_error.hpp) when the link failed – e.g. "USB device was unplugged".
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <utility>
#include <vector>

#include <boost/asio/any_io_executor.hpp>
#include <boost/asio/associated_executor.hpp>
#include <boost/asio/buffer.hpp>
#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/post.hpp>
#include <boost/system/error_code.hpp>

namespace rr::server::usb {

/// A move-only completion `void(error_code, size_t)`; calling it more than once is a bug (the second
/// call does nothing).
class StreamCompletion {
public:
    StreamCompletion() = default;
    template <class F>
    explicit StreamCompletion(F f) : impl_(std::make_unique<Impl<F>>(std::move(f))) {}
    explicit operator bool() const noexcept { return impl_ != nullptr; }
    void operator()(boost::system::error_code ec, std::size_t n) {
        if (auto i = std::move(impl_)) i->call(ec, n);
    }

private:
    struct Base {
        virtual ~Base() = default;
        virtual void call(boost::system::error_code ec, std::size_t n) = 0;
    };
    template <class F>
    struct Impl final : Base {
        explicit Impl(F f) : fn(std::move(f)) {}
        void call(boost::system::error_code ec, std::size_t n) override { fn(ec, n); }
        F fn;
    };
    std::unique_ptr<Base> impl_;
};

/// What a UsbByteStream talks to: the owner of the link's state.
class UsbStreamChannel {
public:
    virtual ~UsbStreamChannel() = default;
    /// Completes with at least one byte, or an error.
    virtual void async_read(std::int32_t stream_id, boost::asio::mutable_buffer buffer, StreamCompletion done) = 0;
    /// Completes once every byte of `buffer` has been taken (copied into a transfer buffer).
    virtual void async_write(std::int32_t stream_id, boost::asio::const_buffer buffer, StreamCompletion done) = 0;
    /// Aborts pending operations (operation_aborted) and ends the stream on the link.
    virtual void close_stream(std::int32_t stream_id) = 0;
};

class UsbByteStream {
public:
    using executor_type = boost::asio::any_io_executor;

    UsbByteStream(executor_type executor, std::shared_ptr<UsbStreamChannel> channel, std::int32_t stream_id)
        : executor_(std::move(executor)), channel_(std::move(channel)), id_(stream_id) {}
    UsbByteStream(UsbByteStream&&) noexcept = default;
    UsbByteStream& operator=(UsbByteStream&&) noexcept = default;
    UsbByteStream(const UsbByteStream&) = delete;
    UsbByteStream& operator=(const UsbByteStream&) = delete;
    ~UsbByteStream() {
        boost::system::error_code ignored;
        close(ignored);
    }

    executor_type get_executor() const noexcept { return executor_; }
    std::int32_t stream_id() const noexcept { return id_; }

    template <class MutableBuffers, class Handler>
    void async_read_some(const MutableBuffers& buffers, Handler&& handler) {
        auto done = wrap(std::forward<Handler>(handler));
        const auto b = first_nonempty<boost::asio::mutable_buffer>(buffers);
        if (!channel_) return done(boost::asio::error::bad_descriptor, 0);
        if (b.size() == 0) return done({}, 0);
        channel_->async_read(id_, b, std::move(done));
    }

    template <class ConstBuffers, class Handler>
    void async_write_some(const ConstBuffers& buffers, Handler&& handler) {
        auto done = wrap(std::forward<Handler>(handler));
        const auto b = first_nonempty<boost::asio::const_buffer>(buffers);
        if (!channel_) return done(boost::asio::error::bad_descriptor, 0);
        if (b.size() == 0) return done({}, 0);
        channel_->async_write(id_, b, std::move(done));
    }

    /// Ends the stream (idempotent). Pending operations complete with operation_aborted.
    void close(boost::system::error_code& ec) {
        ec = {};
        if (auto c = std::move(channel_)) c->close_stream(id_);
    }
    bool is_open() const noexcept { return channel_ != nullptr; }

private:
    template <class Buffer, class Buffers>
    static Buffer first_nonempty(const Buffers& buffers) {
        for (auto it = boost::asio::buffer_sequence_begin(buffers); it != boost::asio::buffer_sequence_end(buffers); ++it) {
            Buffer b(*it);
            if (b.size() != 0) return b;
        }
        return Buffer();
    }

    // The channel invokes the completion from its own context; the handler runs on its associated
    // executor (the pump's strand), kept alive by a work guard until then.
    template <class Handler>
    StreamCompletion wrap(Handler&& handler) {
        auto ex = boost::asio::get_associated_executor(handler, executor_);
        auto work = boost::asio::make_work_guard(ex);
        return StreamCompletion([h = std::forward<Handler>(handler), work = std::move(work)](
                                    boost::system::error_code ec, std::size_t n) mutable {
            auto ex2 = work.get_executor();
            boost::asio::post(ex2, [h = std::move(h), ec, n, w = std::move(work)]() mutable {
                w.reset();
                h(ec, n);
            });
        });
    }

    executor_type executor_;
    std::shared_ptr<UsbStreamChannel> channel_;
    std::int32_t id_ = -1;
};

/// One stream's byte queues at an rr+usb endpoint: received bytes waiting for a read, the pending read
/// and the pending write. Owned and serialised by a UsbStreamChannel implementation.
class UsbStreamBuffers {
public:
    /// Bytes arrived for the stream: a pending read takes what fits, the rest waits here.
    void on_data(std::span<const std::byte> bytes) {
        if (read_done_ && received_ == 0) {
            const std::size_t n = std::min(bytes.size(), read_buffer_.size());
            std::copy_n(bytes.begin(), n, static_cast<std::byte*>(read_buffer_.data()));
            bytes = bytes.subspan(n);
            auto done = std::move(read_done_);
            done({}, n);
        }
        if (!bytes.empty()) {
            if (offset_ > 0 && offset_ == rx_.size()) {
                rx_.clear();
                offset_ = 0;
            }
            rx_.insert(rx_.end(), bytes.begin(), bytes.end());
            received_ = rx_.size() - offset_;
        }
    }
    /// Bytes received and not yet read.
    std::size_t queued() const noexcept { return received_; }

    /// Starts a read; completes at once when bytes are queued (or the stream ended).
    void start_read(boost::asio::mutable_buffer buffer, StreamCompletion done) {
        if (read_done_) return done(boost::asio::error::in_progress, 0);
        if (received_ > 0) {
            const std::size_t n = std::min(buffer.size(), received_);
            std::copy_n(rx_.begin() + static_cast<std::ptrdiff_t>(offset_), n, static_cast<std::byte*>(buffer.data()));
            offset_ += n;
            received_ -= n;
            if (received_ == 0) {
                rx_.clear();
                offset_ = 0;
            } else if (offset_ > (1u << 16) && offset_ * 2 > rx_.size()) {
                rx_.erase(rx_.begin(), rx_.begin() + static_cast<std::ptrdiff_t>(offset_));
                offset_ = 0;
            }
            return done({}, n);
        }
        if (end_) return done(end_, 0);
        read_buffer_ = buffer;
        read_done_ = std::move(done);
    }

    bool write_pending() const noexcept { return static_cast<bool>(write_done_); }
    /// Records the pending write (the owner hands its bytes to the scheduler).
    void start_write(std::size_t size, StreamCompletion done) {
        write_size_ = size;
        write_done_ = std::move(done);
    }
    /// The scheduler consumed the whole pending write.
    void write_drained() {
        if (write_done_) {
            auto done = std::move(write_done_);
            done({}, write_size_);
        }
    }

    /// The stream ended: the pending read gets `read_error` once the queued bytes are read (eof for a
    /// peer close), the pending write `write_error` at once.
    void end(boost::system::error_code read_error, boost::system::error_code write_error) {
        if (!end_) end_ = read_error;
        if (read_done_ && received_ == 0) {
            auto done = std::move(read_done_);
            done(end_, 0);
        }
        if (write_done_) {
            auto done = std::move(write_done_);
            done(write_error, 0);
        }
    }
    /// Like end(), but queued bytes are dropped too (a local close, a failed link).
    void abort(boost::system::error_code error) {
        rx_.clear();
        offset_ = received_ = 0;
        end(error, error);
    }

private:
    std::vector<std::byte> rx_;
    std::size_t offset_ = 0, received_ = 0;
    boost::asio::mutable_buffer read_buffer_;
    StreamCompletion read_done_;
    std::size_t write_size_ = 0;
    StreamCompletion write_done_;
    boost::system::error_code end_;
};

}  // namespace rr::server::usb
