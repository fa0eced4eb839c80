// ByteWriter: appends little-endian integers and byte strings to a std::vector<std::byte>, or to a
// GatherBuffer, where large shared payloads are spliced in instead of copied (write_shared).
//
// The writer never fails; callers reserve the final size first (the message writer computes every
// size before writing) so appends do not reallocate. Not thread-safe (holds a reference to `out`).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "base/codec/endian.hpp"
#include "base/codec/gather_buffer.hpp"

namespace rr {

class ByteWriter {
public:
    explicit ByteWriter(std::vector<std::byte>& out) noexcept : out_(out), start_(out.size()) {}
    explicit ByteWriter(GatherBuffer& out) noexcept
        : out_(out.owned()), start_(out.owned().size()), gather_(&out), spliced_start_(out.spliced_bytes()) {}

    /// Bytes appended since this writer was made (spliced ones included).
    std::size_t written() const noexcept {
        return out_.size() - start_ + (gather_ ? gather_->spliced_bytes() - spliced_start_ : 0);
    }
    std::vector<std::byte>& buffer() noexcept { return out_; }

    template <class T>
    void write(T value) {
        std::array<std::byte, sizeof(T)> b;
        store_le(b.data(), value);
        out_.insert(out_.end(), b.begin(), b.end());
    }
    void write_u8(std::uint8_t v) { out_.push_back(static_cast<std::byte>(v)); }
    void write_u16(std::uint16_t v) { write(v); }
    void write_u32(std::uint32_t v) { write(v); }
    void write_u64(std::uint64_t v) { write(v); }
    void write_i8(std::int8_t v) { write(v); }
    void write_i16(std::int16_t v) { write(v); }
    void write_i32(std::int32_t v) { write(v); }
    void write_i64(std::int64_t v) { write(v); }

    void write_bytes(std::span<const std::byte> bytes) { out_.insert(out_.end(), bytes.begin(), bytes.end()); }
    /// Like write_bytes; into a GatherBuffer, a large range with an owner is spliced, not copied.
    void write_shared(const SharedBytes& bytes) {
        if (gather_) [[unlikely]]
            append_gathered(bytes);
        else
            write_bytes(bytes.bytes());
    }
    void write_string(std::string_view s) {
        auto p = reinterpret_cast<const std::byte*>(s.data());
        out_.insert(out_.end(), p, p + s.size());
    }

private:
    // Out of line so that write_shared stays small enough to inline on the contiguous path.
    [[gnu::noinline]] void append_gathered(const SharedBytes& bytes) { gather_->append(bytes); }

    std::vector<std::byte>& out_;
    std::size_t start_;
    GatherBuffer* gather_ = nullptr;
    std::size_t spliced_start_ = 0;
};

}  // namespace rr
