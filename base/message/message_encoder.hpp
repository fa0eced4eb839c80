// Internal: the two-pass encoder behind message_writer.hpp. measure() validates the message and
// records every entry/element size in pre-order; write() replays them. Not part of the public API.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "base/codec/byte_writer.hpp"
#include "base/message/message_writer.hpp"

namespace rr::detail {

class MessageEncoder {
public:
    explicit MessageEncoder(const Message& message) : m_(message), entries_(message.entries) {}
    /// `header`'s header followed by `entries`, which live elsewhere (`header.entries` is not read).
    MessageEncoder(const Message& header, std::span<const MessageEntry> entries) : m_(header), entries_(entries) {}
    /// `message`'s header followed by one entry already encoded in `message.version` (encode_entry);
    /// `message.entries` must be empty.
    MessageEncoder(const Message& message, SharedBytes encoded_entry)
        : m_(message), encoded_entry_(std::move(encoded_entry)), has_encoded_entry_(true) {}

    /// One entry on its own in format `version` (no local string table: a v4 code must be standard).
    Result<std::uint32_t> measure_entry(const MessageEntry& entry, std::uint16_t version);
    /// Writes the entry measure_entry() measured.
    void write_entry(ByteWriter& w, const MessageEntry& entry, std::uint16_t version);

    /// Validates and measures; returns the total message size.
    Result<std::uint32_t> measure();
    /// Writes the measured message. Precondition: measure() succeeded.
    void write(ByteWriter& w);

    /// Bytes of the last measured message or entry that a GatherBuffer splices instead of copying.
    std::uint64_t spliced_bytes() const noexcept { return spliced_; }

private:
    // message_writer_v2.cpp
    Result<std::uint32_t> measure_v2();
    Result<std::uint64_t> measure_entry_v2(const MessageEntry& entry);
    Result<std::uint64_t> measure_element_v2(const MessageElement& e);
    void write_v2(ByteWriter& w);
    void write_entry_v2(ByteWriter& w, const MessageEntry& entry);
    void write_element_v2(ByteWriter& w, const MessageElement& e);

    // message_writer_v4.cpp
    Result<std::uint32_t> measure_v4();
    Result<std::uint64_t> measure_entry_v4(const MessageEntry& entry);
    Result<std::uint64_t> measure_element_v4(const MessageElement& e);
    Result<std::uint64_t> measure_name_v4(const std::string& s, const std::optional<std::uint32_t>& code);
    void write_v4(ByteWriter& w);
    void write_entry_v4(ByteWriter& w, const MessageEntry& entry);
    void write_element_v4(ByteWriter& w, const MessageElement& e);

    // message_writer.cpp
    /// Checks type/data/children agree; returns the payload bytes of raw data (0 for nested/void).
    Result<std::uint64_t> check_payload(const MessageElement& e) const;
    /// Reserves a pre-order slot for a size computed after the children.
    std::size_t reserve_size_slot();
    std::uint32_t next_size();
    void count_splice(const SharedBytes& b) noexcept {
        if (GatherBuffer::splices(b)) spliced_ += b.size();
    }

    /// Entries in the message: its own, or the one already encoded.
    std::size_t entry_count() const noexcept { return has_encoded_entry_ ? 1 : entries_.size(); }

    const Message& m_;
    std::span<const MessageEntry> entries_;  ///< the entries encoded (m_.entries unless given apart)
    SharedBytes encoded_entry_;
    bool has_encoded_entry_ = false;
    std::uint64_t spliced_ = 0;
    /// Entry and element sizes, pre-order: the first kInlineSizes in the encoder itself, so a message
    /// of a few entries and elements is encoded without allocating for them.
    static constexpr std::size_t kInlineSizes = 16;
    std::array<std::uint32_t, kInlineSizes> inline_sizes_{};
    std::vector<std::uint32_t> more_sizes_;
    std::size_t size_count_ = 0;
    std::uint32_t& size_slot(std::size_t i) { return i < kInlineSizes ? inline_sizes_[i] : more_sizes_[i - kInlineSizes]; }
    std::size_t cursor_ = 0;
    std::uint32_t total_ = 0;
    std::uint32_t header_size_ = 0;
    std::uint8_t v4_flags_ = 0;
    std::vector<std::uint32_t> local_codes_;  // codes of the local table being written, sorted
};

/// Bytes of a v4 XLen string (uint_x length + bytes).
std::uint64_t xlen_size(std::size_t n) noexcept;

}  // namespace rr::detail
