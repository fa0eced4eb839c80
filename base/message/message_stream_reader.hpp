// MessageStreamReader: incremental framing of the RR stream protocol (wire.md §6; STD
// basic_stream_protocol.md). Messages follow each other on the byte stream, each starting with the
// 8-byte preamble "RRAC" + uint32 MessageSize; there is no resynchronisation after an error.
//
// In: bytes in any split (feed). Out: whole messages in arrival order, as SharedBytes frames (one
// owned buffer per message; forward it without copying, or decode it with element payloads as views
// into it) or as decoded Messages. Not thread-safe.
//
// Limits: the magic is checked as soon as its bytes arrive; MessageSize is checked against
// kMinMessageSize and Limits::max_message_size right after the preamble, before any buffer for the
// message is allocated. A message up to 64 KiB gets its final buffer at once (one allocation with
// its reference count); one up to kReusedFrameBytes reuses the last such buffer when nothing decoded
// from it is still held (a call's request and reply need no allocation for their frames). A larger
// one grows with the bytes that actually arrive (first 64 KiB, then doubling, and to MessageSize once
// a quarter of it has arrived), so a peer cannot make the reader allocate more than 64 KiB or 4 ×
// what it has sent. The host may read a large message's bytes straight into that buffer
// (read_space(), then feed() with those bytes): they are not copied again.
// Errors (all fatal, as in CORE, which closes the connection): ProtocolError (bad magic, MessageSize
// below a header, or a frame that does not decode in take_message), BufferLimitViolation (MessageSize
// over the limit, or a decode limit). After the first error every call fails with that error and no
// further frame is yielded, including frames completed before the error.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <deque>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "base/codec/limits.hpp"
#include "base/codec/shared_bytes.hpp"
#include "base/message/message_reader.hpp"

namespace rr {

class MessageStreamReader {
public:
    explicit MessageStreamReader(const Limits& limits = {}) : limits_(limits) {}

    /// Consumes all of `bytes`; complete messages become available to take_frame/take_message.
    /// Errors: see above; once failed, always failed.
    Result<void> feed(std::span<const std::byte> bytes);

    /// Free space in the buffer of the large message being assembled (over 64 KiB, at least
    /// kDirectReadMinBytes of it still to come), for the host to read the message's next bytes into;
    /// empty otherwise. The span ends at or before the message's end. Passing those bytes (the span's
    /// start, at most its size) to feed() next adds them without a copy; any other feed() is as usual.
    /// May grow the buffer, under the rule above.
    std::span<std::byte> read_space() {
        // Inline: the pump asks before every read, and between large messages the answer is no.
        if (!large_ || expected_ - large_fill_ < kDirectReadMinBytes || error_) return {};
        return large_read_space();
    }

    /// The next complete message, bytes exactly as received; nullopt if none is complete yet.
    std::optional<SharedBytes> take_frame();

    /// Decodes the next complete message. ok(nullopt) if none is complete; a decode error is fatal.
    Result<std::optional<Message>> take_message(const DecodeContext* context = nullptr);

    /// Changes the MessageSize limit (e.g. from Limits::max_pre_session_message_size to
    /// max_message_size once a client session exists, wire.md §6.4). Applies to messages whose
    /// preamble completes after the call; a message already being assembled keeps its checked size.
    void set_max_message_size(std::size_t bytes) noexcept { limits_.max_message_size = bytes; }
    std::size_t max_message_size() const noexcept { return limits_.max_message_size; }

    /// Number of complete messages waiting.
    std::size_t ready_count() const noexcept { return ready_.size(); }
    /// Bytes of the message being assembled (0 between messages).
    std::size_t partial_bytes() const noexcept { return preamble_fill_ + (frame_ ? frame_fill_ : large_fill_); }
    /// Bytes allocated for the message being assembled (for per-connection memory accounting).
    std::size_t partial_capacity() const noexcept {
        return frame_ ? std::max(expected_, kReusedFrameBytes) : large_capacity_;
    }

    /// Messages up to this size are read into one buffer, reused from message to message.
    static constexpr std::size_t kReusedFrameBytes = 512;
    /// read_space() offers no span for less than this (a smaller rest goes through the host's buffer).
    static constexpr std::size_t kDirectReadMinBytes = 16 * 1024;
    bool failed() const noexcept { return error_.has_value(); }
    /// The error that stopped the reader, or nullptr.
    const RRError* error() const noexcept { return error_ ? &*error_ : nullptr; }

private:
    Unexpected stop(RRError e);
    /// A buffer for a message of `size` ≤ kInitialBufferBytes bytes: spare_frame_ when it fits and
    /// nothing else holds it.
    std::shared_ptr<std::byte[]> small_frame(std::size_t size);
    /// read_space() once a large message is being assembled.
    std::span<std::byte> large_read_space();
    /// Moves the large message's bytes so far into a new buffer of `capacity` bytes.
    void grow_large(std::size_t capacity);

    static constexpr std::size_t kInitialBufferBytes = 64 * 1024;

    Limits limits_;
    std::array<std::byte, kMessagePreambleBytes> preamble_{};
    std::size_t preamble_fill_ = 0;
    std::size_t expected_ = 0;        // MessageSize of the message being assembled, 0 while reading a preamble
    std::shared_ptr<std::byte[]> large_;  // a message over kInitialBufferBytes being assembled, preamble included
    std::size_t large_capacity_ = 0;
    std::size_t large_fill_ = 0;
    std::shared_ptr<std::byte[]> frame_;  // a message up to kInitialBufferBytes being assembled (its final buffer)
    std::shared_ptr<std::byte[]> spare_frame_;  // the last buffer of kReusedFrameBytes, reused once released
    std::size_t frame_fill_ = 0;
    std::deque<SharedBytes> ready_;
    std::optional<RRError> error_;
};

}  // namespace rr
