// Decoding RR messages from bytes: message format v2 (wire.md §1) and v4 (wire.md §2).
//
// decode_message() takes one whole message and dispatches on its MessageVersion field (2 or 4).
// Element payloads (raw arrays, strings) in the result are SharedBytes views into the input buffer:
// no copy and no allocation per payload.
//
// Order of checks (message_v2.md §Common Message Header): magic "RRAC"; MessageSize at least
// kMinMessageSize and at most Limits::max_message_size; MessageSize equal to the bytes given; version;
// then every header/entry/element size is checked against the bytes that remain in its parent and must
// end exactly where it says; every count is checked against the bytes left (each item has a minimum
// size) and against Limits before anything is reserved.
//
// Errors: ProtocolError — bad magic, unknown version, truncation, sizes that do not add up, an unknown
//         data type, a void element with DataCount ≠ 0, v4 varints in their 64-bit form, an unknown
//         string-table code, a v4 field given both as string and as code (or name and number), nesting
//         deeper than Limits::max_nesting_depth.
//         BufferLimitViolation — MessageSize over Limits::max_message_size, more entries than
//         Limits::max_entries, more elements (all levels) than Limits::max_elements.
// Never UB, crash or hang on any input (fuzzed: test/fuzz/fuzz_message_reader.cpp).
//
// What the model records so that re-encoding is byte-identical (for inputs written with CORE's
// rules, i.e. shortest varints and CORE's entry/element flag choices):
//  * v4 header flags are kept in MessageHeader::v4_flags, string-table codes in the *_code fields,
//    the local table in MessageHeader::string_table (wire order), Extended blobs as bytes. (Not with a
//    DecodeContext whose keep_string_table_codes is false: then only the resolved strings remain.)
//  * Element numbers: v4 ELEMENT_NUMBER → MessageElement::number (name empty). In v2 a decimal
//    name is read back as a number (name cleared) only where CORE writes numbers: children of
//    vector_t, list_t and pod_array_t, and the top-level elements of PipePacketRet entries
//    (CORE PipeMember.cpp acks), and only for canonical text (element_number.hpp).
//  * Not kept: the v2 entry "reserved" field (CORE writes 0, ignores it), the v4 element flag 0x40
//    (reserved), v4 entry/element flags that announce an empty or zero optional field.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "base/codec/limits.hpp"
#include "base/codec/shared_bytes.hpp"
#include "base/message/message.hpp"

namespace rr {

/// What a v4 decoder needs from the connection: values for header fields the sender omitted
/// (routing/endpoint info, wire.md §2.3) and which string tables are in force (wire.md §2.6).
struct DecodeContext {
    NodeID local_node_id;
    NodeID remote_node_id;
    std::uint32_t local_endpoint = 0;
    std::uint32_t remote_endpoint = 0;
    /// Even string-table codes are looked up in the standard table only if this is set (the
    /// STANDARD_TABLE capability was negotiated); otherwise they are a ProtocolError, as in CORE.
    /// Odd codes always use the message's own table. Without a context both are accepted.
    bool standard_string_table = true;
    /// Whether the *_code fields, MessageHeader::string_table and the STRING_TABLE flag of
    /// MessageHeader::v4_flags keep what was on the wire (so the message re-encodes byte-identical).
    /// A connection sets this false, as CORE's receiver does (StringTable::MessageReplaceCodesWithStrings):
    /// codes name strings only within the message and connection they came in, so its entries then
    /// hold plain strings and may be forwarded, stored or re-encoded for any other connection
    /// (wire.md §2.6). Without a context codes are kept.
    bool keep_string_table_codes = true;
};

/// "RRAC" + uint32 MessageSize: the first bytes of every message on a stream (wire.md §6).
inline constexpr std::size_t kMessagePreambleBytes = 8;
/// Smallest MessageSize that can hold a fixed header (v4: magic, size, version, HeaderLen, flags).
inline constexpr std::size_t kMinMessageSize = 12;

/// Checks the 8-byte preamble. Returns MessageSize.
/// Errors: ProtocolError (fewer than 8 bytes, bad magic, MessageSize < kMinMessageSize),
/// BufferLimitViolation (MessageSize > limits.max_message_size).
Result<std::uint32_t> read_message_preamble(std::span<const std::byte> bytes, const Limits& limits = {});

/// A decoded header with the framing fields the model does not carry.
struct MessageHeaderInfo {
    std::uint16_t version = 0;
    std::uint32_t message_size = 0;  ///< bytes, whole message
    std::uint32_t header_size = 0;   ///< bytes from offset 0 to the first entry
    std::uint32_t entry_count = 0;
    MessageHeader header;
};

/// Decodes only the header of the whole message in `message` (MessageSize must equal its size), e.g.
/// to route a frame without decoding its entries. Errors: as decode_message, for the header.
Result<MessageHeaderInfo> decode_message_header(std::span<const std::byte> message, const Limits& limits = {},
                                                const DecodeContext* context = nullptr);

/// Decodes one complete message held in `buffer` (exactly one message: MessageSize == buffer size).
/// Element payloads in the result are views into `buffer`: no copy. `context` fills the v4 header
/// fields a sender omitted (all-zero NodeIDs and endpoints when null).
Result<Message> decode_message(SharedBytes buffer, const Limits& limits = {}, const DecodeContext* context = nullptr);
/// As above, decoding the entries into `storage` (cleared first; its capacity is reused, e.g. a vector
/// from an EntryVectorPool, base/message/entry_vector_pool.hpp).
Result<Message> decode_message(SharedBytes buffer, const Limits& limits, const DecodeContext* context,
                               std::vector<MessageEntry> storage);
/// As above, into `out`, which must be a default-constructed Message except for `out.entries`: the
/// entries are decoded into that vector (cleared first; its capacity is reused). A host decodes a frame
/// straight into the event or slot it will be handled from (no move of the message afterwards). On an
/// error `out` holds part of the message and is to be dropped.
Result<void> decode_message_into(Message& out, const SharedBytes& buffer, const Limits& limits,
                                 const DecodeContext* context);

}  // namespace rr
