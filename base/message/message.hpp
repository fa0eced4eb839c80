// The RR message model: Message = MessageHeader + MessageEntry list; MessageEntry = fixed fields +
// MessageElement list; MessageElement = fixed fields + raw array data or nested elements.
//
// Layouts: wire.md §1 (message format v2), §2 (message format v4). This header holds the in-memory
// model only; reading and writing bytes live in base/message/message_reader.hpp and message_writer.hpp.
//
// The model is version-neutral. Fields that only v4 can carry (priority, string-table codes, extended
// blobs, element numbers) are kept so that a message decoded from bytes re-encodes byte-identical in
// the version it was read in, and so that v2 <-> v4 conversion is lossless for everything CORE sends.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "base/codec/shared_bytes.hpp"
#include "base/error/rr_error.hpp"
#include "base/message/data_types.hpp"
#include "base/message/entry_type.hpp"
#include "base/names/node_id.hpp"

namespace rr {

/// One element (wire.md §1.4, §2.5).
///
/// Identity: either `name` or `number`. An element "has a number" when `number` is set; then `name`
/// is ignored on write (v2 writes the number as decimal text, v4 uses ELEMENT_NUMBER). The v2 reader
/// sets `number` (and clears `name`) for children of numbered containers (vector_t, list_t,
/// pod_array_t) and for the top-level elements of PipePacketRet entries (CORE PipeMember.cpp numbers
/// its acks) whose name is a canonical decimal int32, so v2 and v4 decode to the same model.
///
/// String-table codes: `name`/`type_name` always hold the text (the reader resolves codes); a code
/// only tells the v4 writer to send the code instead of the text (see string_table.hpp).
///
/// Payload: for is_nested(type) the children are in `elements` and `data` is empty; otherwise `data`
/// holds the raw little-endian array (DataCount = data.size() / data_type_size(type); string_t holds
/// UTF-8 bytes; void_t holds nothing).
struct MessageElement {
    std::string name;
    std::optional<std::int32_t> number;
    DataTypes type = DataTypes::void_t;
    std::string type_name;
    std::string metadata;
    std::string extended;  ///< v4 Extended blob (opaque bytes); empty when absent

    /// v4 string-table codes this element was read with (or should be written with). When set, the
    /// v4 writer emits the code instead of (ELEMENT_NAME_CODE / ELEMENT_TYPE_NAME_CODE) the string.
    std::optional<std::uint32_t> name_code;
    std::optional<std::uint32_t> type_name_code;

    SharedBytes data;
    std::vector<MessageElement> elements;

    /// DataCount as written on the wire: array item count, child count for nested types, 0 for void.
    std::uint32_t data_count() const noexcept;

    /// First child whose name equals `n` (numbers never match), or nullptr.
    const MessageElement* find(std::string_view n) const noexcept;

    /// Field-by-field equality; `data` compares bytes, not owners.
    friend bool operator==(const MessageElement&, const MessageElement&) = default;
};

/// One entry (wire.md §1.3, §2.4).
struct MessageEntry {
    MessageEntryType entry_type = MessageEntryType::Null;
    std::string service_path;
    std::string member_name;
    std::optional<std::uint32_t> service_path_code;  ///< v4 SERVICE_PATH_CODE, see MessageElement
    std::optional<std::uint32_t> member_name_code;   ///< v4 MEMBER_NAME_CODE
    std::uint32_t request_id = 0;
    MessageErrorType error = MessageErrorType::None;
    std::string metadata;
    std::string extended;  ///< v4 only
    std::vector<MessageElement> elements;

    /// First top-level element named `n`, or nullptr.
    const MessageElement* find(std::string_view n) const noexcept;

    friend bool operator==(const MessageEntry&, const MessageEntry&) = default;
};

/// v4 header flags (wire.md §2.3).
namespace message_flags {
inline constexpr std::uint8_t routing_info = 0x01;
inline constexpr std::uint8_t endpoint_info = 0x02;
inline constexpr std::uint8_t priority = 0x04;
inline constexpr std::uint8_t unreliable = 0x08;
inline constexpr std::uint8_t meta_info = 0x10;
inline constexpr std::uint8_t string_table = 0x20;
inline constexpr std::uint8_t multiple_entries = 0x40;
inline constexpr std::uint8_t extended = 0x80;
}  // namespace message_flags

/// v4 entry flags (wire.md §2.4).
namespace entry_flags {
inline constexpr std::uint8_t service_path_str = 0x01;
inline constexpr std::uint8_t service_path_code = 0x02;
inline constexpr std::uint8_t member_name_str = 0x04;
inline constexpr std::uint8_t member_name_code = 0x08;
inline constexpr std::uint8_t request_id = 0x10;
inline constexpr std::uint8_t error = 0x20;
inline constexpr std::uint8_t meta_info = 0x40;
inline constexpr std::uint8_t extended = 0x80;
}  // namespace entry_flags

/// v4 element flags (wire.md §2.5). 0x40 is reserved.
namespace element_flags {
inline constexpr std::uint8_t element_name_str = 0x01;
inline constexpr std::uint8_t element_name_code = 0x02;
inline constexpr std::uint8_t element_number = 0x04;
inline constexpr std::uint8_t element_type_name_str = 0x08;
inline constexpr std::uint8_t element_type_name_code = 0x10;
inline constexpr std::uint8_t meta_info = 0x20;
inline constexpr std::uint8_t extended = 0x80;
}  // namespace element_flags

/// Message header (wire.md §1.2, §2.3).
struct MessageHeader {
    NodeID sender_node_id;
    NodeID receiver_node_id;
    std::string sender_node_name;
    std::string receiver_node_name;
    std::uint32_t sender_endpoint = 0;
    std::uint32_t receiver_endpoint = 0;
    std::string metadata;
    std::uint16_t message_id = 0;
    std::uint16_t message_res_id = 0;

    // --- v4 only ---
    /// Header flags. When decoding v4 this is what was on the wire (v2 decodes leave it empty). When
    /// encoding v4, `std::nullopt` means "compute as CORE does" (default_v4_flags, full routing); a
    /// value is honoured exactly, which is how routing/endpoint omission on a negotiated connection is
    /// expressed (encode_message refuses flags that would drop a field holding data). Reset it before
    /// re-sending a decoded message on another connection.
    std::optional<std::uint8_t> v4_flags;
    std::uint16_t priority = 0;
    /// Message-local string table (odd codes), in wire order.
    std::vector<std::pair<std::uint32_t, std::string>> string_table;
    std::string extended;

    friend bool operator==(const MessageHeader&, const MessageHeader&) = default;
};

/// A whole message (wire.md §1, §2). `version` is 2 or 4: the version it was decoded from, or the
/// version to encode in.
struct Message {
    std::uint16_t version = 2;
    MessageHeader header;
    std::vector<MessageEntry> entries;

    friend bool operator==(const Message&, const Message&) = default;
};

}  // namespace rr
