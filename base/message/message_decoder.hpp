// Internal: the decoder shared by message_reader.cpp (framing, dispatch), message_reader_v2.cpp and
// message_reader_v4.cpp. Not part of the public API; include message_reader.hpp instead.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "base/codec/byte_reader.hpp"
#include "base/message/message_reader.hpp"

namespace rr::detail {

class MessageDecoder {
public:
    MessageDecoder(std::span<const std::byte> message, const SharedBytes* owner, const Limits& limits,
                   const DecodeContext* context)
        : message_(message), owner_(owner), limits_(limits), context_(context) {}

    /// Header of the message (both versions): the framing fields into `info`, the header into
    /// `header` (default-constructed: fields the message leaves out keep their defaults, or come from
    /// the DecodeContext). `body` is left over the entry bytes.
    Result<void> read_header(ByteReader& body, MessageHeaderInfo& info, MessageHeader& header);
    /// Entries after the header (`info` and `header` as read_header left them), decoded into `entries`
    /// (cleared first; its capacity is reused); `body` must end exactly after the last one.
    Result<void> read_entries(const MessageHeaderInfo& info, const MessageHeader& header, ByteReader& body,
                              std::vector<MessageEntry>& entries);

private:
    // v2 (message_reader_v2.cpp)
    Result<void> read_header_v2(ByteReader& r, MessageHeaderInfo& info, MessageHeader& h);
    Result<void> read_entry_v2(ByteReader& r, MessageEntry& entry);
    Result<void> read_element_v2(ByteReader& r, MessageElement& e, std::size_t depth, bool numbered);

    // v4 (message_reader_v4.cpp)
    Result<void> read_header_v4(ByteReader& r, MessageHeaderInfo& info, MessageHeader& h);
    Result<void> read_entry_v4(ByteReader& r, MessageEntry& entry);
    Result<void> read_element_v4(ByteReader& r, MessageElement& e, std::size_t depth);
    /// The string `code` names (a view into the header's local table or the standard table).
    Result<std::string_view> resolve_code(std::uint32_t code) const;
    /// Whether decoded names keep their codes (DecodeContext::keep_string_table_codes).
    bool keep_codes() const noexcept { return !context_ || context_->keep_string_table_codes; }

    // shared (message_reader.cpp)
    /// Raw array, void or nested payload of `e` after its DataCount; `r` must end with it.
    Result<void> read_payload(ByteReader& r, MessageElement& e, std::uint32_t data_count, std::size_t depth,
                              bool numbered_children);
    /// Checks `count` items of at least `min_item_bytes` each against the bytes left in `r` and the
    /// element budget (when `elements`), before anything is reserved.
    Result<void> check_count(const ByteReader& r, std::uint64_t count, std::size_t min_item_bytes, bool elements,
                             const char* what);
    /// Reader over the next `size - consumed` bytes of `r` for a size field that counts itself.
    Result<ByteReader> sized_part(ByteReader& r, std::uint64_t size, std::size_t consumed, std::size_t min_size,
                                  const char* what);
    Unexpected error(MessageErrorType type, const ByteReader& at, std::string what) const;
    std::size_t offset_of(const ByteReader& r) const noexcept;
    SharedBytes view(std::span<const std::byte> bytes) const;

    std::span<const std::byte> message_;
    const SharedBytes* owner_;  // null: header-only decode, no payload views needed
    const Limits& limits_;
    const DecodeContext* context_;
    std::uint16_t version_ = 0;
    std::size_t elements_seen_ = 0;
    const std::vector<std::pair<std::uint32_t, std::string>>* local_table_ = nullptr;  // v4 header table
    // Sorted (code, position), built only for a table longer than kLinearLocalTable (a small table is
    // searched in place: no allocation per message).
    std::vector<std::pair<std::uint32_t, std::size_t>> local_index_;
    static constexpr std::size_t kLinearLocalTable = 16;
};

/// Drops what a message's string table left in its header once its entries hold plain strings
/// (DecodeContext::keep_string_table_codes false): the local table and the STRING_TABLE flag.
void forget_string_table(MessageHeader& header) noexcept;

/// Whether children of an element of type `t` carry element numbers in CORE (wire.md §3.2).
constexpr bool has_numbered_children(DataTypes t) noexcept {
    return t == DataTypes::vector_t || t == DataTypes::list_t || t == DataTypes::pod_array_t;
}

}  // namespace rr::detail
