#include "base/message/message_stream_reader.hpp"

#include <algorithm>

namespace rr {

Unexpected MessageStreamReader::stop(RRError e) {
    error_ = e;
    return fail(std::move(e));
}

Result<void> MessageStreamReader::feed(std::span<const std::byte> bytes) {
    if (error_) return fail(*error_);
    while (!bytes.empty()) {
        if (expected_ == 0) {
            // Preamble: check the magic as soon as its bytes are here, the size before allocating.
            const std::size_t n = std::min(bytes.size(), kMessagePreambleBytes - preamble_fill_);
            std::copy_n(bytes.begin(), n, preamble_.begin() + static_cast<std::ptrdiff_t>(preamble_fill_));
            preamble_fill_ += n;
            bytes = bytes.subspan(n);
            static constexpr char kMagic[] = "RRAC";
            for (std::size_t i = 0; i < std::min<std::size_t>(preamble_fill_, 4); ++i)
                if (preamble_[i] != static_cast<std::byte>(kMagic[i]))
                    return stop(make_error(MessageErrorType::ProtocolError, "bad message magic (expected RRAC)"));
            if (preamble_fill_ < kMessagePreambleBytes) return {};
            auto size = read_message_preamble(preamble_, limits_);
            if (!size) return stop(size.error());
            expected_ = *size;
            preamble_fill_ = 0;
#if defined(__cpp_lib_smart_ptr_for_overwrite)
            if (expected_ <= kInitialBufferBytes) {
                // Small message: its final buffer at once, bytes and reference count in one allocation.
                frame_ = small_frame(expected_);
                std::copy(preamble_.begin(), preamble_.end(), frame_.get());
                frame_fill_ = kMessagePreambleBytes;
            }
#endif
            if (!frame_) {
                grow_large(std::min(expected_, kInitialBufferBytes));
                std::copy(preamble_.begin(), preamble_.end(), large_.get());
                large_fill_ = kMessagePreambleBytes;
            }
        }
        if (frame_) {
            const std::size_t n = std::min(bytes.size(), expected_ - frame_fill_);
            std::copy_n(bytes.begin(), n, frame_.get() + frame_fill_);
            frame_fill_ += n;
            bytes = bytes.subspan(n);
            if (frame_fill_ == expected_) {
                std::span<const std::byte> view(frame_.get(), expected_);
                ready_.emplace_back(std::shared_ptr<const void>(std::move(frame_)), view);
                frame_fill_ = 0;
                expected_ = 0;
            }
            continue;
        }
        const std::size_t n = std::min(bytes.size(), expected_ - large_fill_);
        if (bytes.data() != large_.get() + large_fill_) {  // else the host read them in place (read_space)
            if (large_fill_ + n > large_capacity_) {
                // Grow with what arrived: doubling, and the whole MessageSize once a quarter of it is
                // here (fewer re-copies of a large message; still at most 4 × the bytes received).
                const std::size_t arrived = large_fill_ + n;
                const std::size_t grown = 4 * arrived >= expected_ ? expected_ : std::max(arrived, 2 * large_capacity_);
                grow_large(std::min(expected_, grown));
            }
            std::copy_n(bytes.data(), n, large_.get() + large_fill_);
        }
        large_fill_ += n;
        bytes = bytes.subspan(n);
        if (large_fill_ == expected_) {
            std::span<const std::byte> view(large_.get(), expected_);
            ready_.emplace_back(std::shared_ptr<const void>(std::move(large_)), view);
            large_capacity_ = 0;
            large_fill_ = 0;
            expected_ = 0;
        }
    }
    return {};
}

#if defined(__cpp_lib_smart_ptr_for_overwrite)
std::shared_ptr<std::byte[]> MessageStreamReader::small_frame(std::size_t size) {
    if (size > kReusedFrameBytes) return std::make_shared_for_overwrite<std::byte[]>(size);
    // Only this reader holds the last small buffer once everything decoded from it is released (the
    // count cannot rise meanwhile: only a holder can copy it), so its bytes may be overwritten.
    if (!spare_frame_ || spare_frame_.use_count() != 1)
        spare_frame_ = std::make_shared_for_overwrite<std::byte[]>(kReusedFrameBytes);
    return spare_frame_;
}
#endif

std::span<std::byte> MessageStreamReader::large_read_space() {
    if (large_capacity_ - large_fill_ < kDirectReadMinBytes) {
        // The growth rule of feed(): the whole MessageSize once a quarter has arrived, else doubling
        // (the buffer is at least 3/4 full here, so still at most 4 × the bytes received).
        const std::size_t grown = 4 * large_fill_ >= expected_ ? expected_ : 2 * large_capacity_;
        grow_large(std::min(expected_, grown));
    }
    return {large_.get() + large_fill_, large_capacity_ - large_fill_};
}

void MessageStreamReader::grow_large(std::size_t capacity) {
    // Not zeroed: every byte is written before it is read.
    std::shared_ptr<std::byte[]> grown(new std::byte[capacity]);
    if (large_fill_ != 0) std::copy_n(large_.get(), large_fill_, grown.get());
    large_ = std::move(grown);
    large_capacity_ = capacity;
}

std::optional<SharedBytes> MessageStreamReader::take_frame() {
    if (error_ || ready_.empty()) return std::nullopt;
    SharedBytes frame = std::move(ready_.front());
    ready_.pop_front();
    return frame;
}

Result<std::optional<Message>> MessageStreamReader::take_message(const DecodeContext* context) {
    if (error_) return fail(*error_);
    auto frame = take_frame();
    if (!frame) return std::optional<Message>{};
    auto m = decode_message(std::move(*frame), limits_, context);
    if (!m) return stop(m.error());
    return std::optional<Message>(std::move(*m));
}

}  // namespace rr
