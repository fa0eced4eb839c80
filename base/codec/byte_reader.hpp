// ByteReader: a bounded cursor over received bytes (STYLE "Bounded reads").
//
// Every read checks the bytes left first and returns Result; nothing ever reads past the end of the
// span. A failed read leaves the cursor where it was. Errors: ProtocolError ("truncated") for reads
// past the end; count × size overflow in take_array is also a ProtocolError.
// The reader does not own the bytes; the span must outlive it. Not thread-safe (plain value type).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "base/codec/endian.hpp"
#include "base/error/rr_error.hpp"

namespace rr {

class ByteReader {
public:
    ByteReader() = default;
    explicit ByteReader(std::span<const std::byte> bytes) noexcept : bytes_(bytes) {}

    /// Offset of the cursor from the start of the span, bytes.
    std::size_t position() const noexcept { return pos_; }
    /// Bytes left after the cursor.
    std::size_t remaining() const noexcept { return bytes_.size() - pos_; }
    bool at_end() const noexcept { return pos_ == bytes_.size(); }
    /// The whole span the reader was built over.
    std::span<const std::byte> bytes() const noexcept { return bytes_; }

    /// The next `n` bytes, advancing past them.
    Result<std::span<const std::byte>> take(std::size_t n) {
        if (n > remaining()) return truncated(n);
        auto s = bytes_.subspan(pos_, n);
        pos_ += n;
        return s;
    }

    /// `count` items of `item_size` bytes each; count × item_size is overflow-checked.
    Result<std::span<const std::byte>> take_array(std::size_t count, std::size_t item_size) {
        if (item_size != 0 && count > remaining() / item_size) return too_many(count, item_size);
        return take(count * item_size);
    }

    /// A reader over the next `n` bytes (positions restart at 0), advancing past them.
    Result<ByteReader> sub_reader(std::size_t n) {
        auto s = take(n);
        if (!s) return s.take_error();
        return ByteReader(*s);
    }

    Result<void> skip(std::size_t n) {
        if (n > remaining()) return truncated(n);
        pos_ += n;
        return {};
    }

    /// `n` bytes as text (no UTF-8 validation, as CORE). A char view of bytes is aliasing-safe; no
    /// integer is ever read through a cast pointer.
    Result<std::string_view> read_string(std::size_t n) {
        auto s = take(n);
        if (!s) return s.take_error();
        return std::string_view(reinterpret_cast<const char*>(s->data()), s->size());
    }

    /// A little-endian integer of sizeof(T) bytes.
    template <class T>
    Result<T> read() {
        if (sizeof(T) > remaining()) return truncated(sizeof(T));
        T v = load_le<T>(bytes_.data() + pos_);
        pos_ += sizeof(T);
        return v;
    }
    Result<std::uint8_t> read_u8() { return read<std::uint8_t>(); }
    Result<std::uint16_t> read_u16() { return read<std::uint16_t>(); }
    Result<std::uint32_t> read_u32() { return read<std::uint32_t>(); }
    Result<std::uint64_t> read_u64() { return read<std::uint64_t>(); }
    Result<std::int8_t> read_i8() { return read<std::int8_t>(); }
    Result<std::int16_t> read_i16() { return read<std::int16_t>(); }
    Result<std::int32_t> read_i32() { return read<std::int32_t>(); }
    Result<std::int64_t> read_i64() { return read<std::int64_t>(); }

private:
    Unexpected truncated(std::size_t wanted) const;
    Unexpected too_many(std::size_t count, std::size_t item_size) const;

    std::span<const std::byte> bytes_;
    std::size_t pos_ = 0;
};

}  // namespace rr
