// Encoding RR messages to bytes: message format v2 (wire.md §1) and v4 (wire.md §2).
//
// encode_message() writes `message` in `message.version` (2 or 4). It first measures the whole message
// (validating it), then reserves the exact size once and writes; on error nothing is appended.
//
// Format 4 follows CORE's writer (Message.cpp UpdateHeader4/UpdateData4, wire.md §2.3–§2.5) so that
// our bytes equal CORE's:
//  * Header flags: MessageHeader::v4_flags if set, honoured exactly (this is how a sender on a
//    negotiated connection omits ROUTING_INFO / ENDPOINT_INFO, and how a decoded message re-encodes
//    byte-identically); otherwise default_v4_flags(message).
//  * Entry flags: SERVICE_PATH_STR / MEMBER_NAME_STR always (even for empty strings) unless the
//    *_code field is set, then the *_CODE flag instead; REQUEST_ID if ≠ 0; ERROR if ≠ 0; META_INFO if
//    MetaData is non-empty; EXTENDED if Extended is non-empty.
//  * Element flags: ELEMENT_NUMBER if `number` is set, else ELEMENT_NAME_CODE if `name_code` is set,
//    else ELEMENT_NAME_STR; ELEMENT_TYPE_NAME_CODE if `type_name_code` is set, else
//    ELEMENT_TYPE_NAME_STR if the type name is non-empty; META_INFO / EXTENDED if non-empty.
// Format 2 writes numbers as decimal ElementNames and ignores the v4-only fields (codes, priority,
// string table, Extended blobs, v4_flags), as CORE's v2 writer does. Strings must always be filled in;
// a *_code is only an encoding choice for format 4.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "base/codec/gather_buffer.hpp"
#include "base/message/message.hpp"

namespace rr {

/// CORE's v4 header flags for `message` with full routing: ROUTING_INFO | ENDPOINT_INFO, plus
/// META_INFO if MetaData is non-empty or MessageID/MessageResID ≠ 0, MULTIPLE_ENTRIES unless there is
/// exactly one entry, STRING_TABLE if the local table is non-empty, EXTENDED if Extended is non-empty,
/// PRIORITY if priority ≠ 0 (CORE never sets the last one; it is kept so no field is dropped).
/// CORE clears ROUTING_INFO | ENDPOINT_INFO on a negotiated connection when the header names exactly
/// (this node, peer, local endpoint, remote endpoint), except for a message made of one entry with
/// EntryType < 500 (ASIOStreamBaseTransport.cpp); that choice belongs to the session.
std::uint8_t default_v4_flags(const Message& message) noexcept;
/// The same for a message of `header` and `entry_count` entries (one already encoded, see below).
std::uint8_t default_v4_flags(const MessageHeader& header, std::size_t entry_count) noexcept;

/// Exact encoded size of `message`, bytes. Errors: as encode_message.
Result<std::size_t> encoded_size(const Message& message);

/// Encodes `message` in `message.version` (2 or 4), appending to `out`.
/// Errors: InvalidArgument — unknown version; more than 65535 entries; a v2 string over 65535 bytes,
/// more than 65535 elements in a v2 entry, a v2 header over 65535 bytes; a message, entry or element
/// over 4 GiB; an element type that cannot travel (is_wire_type false); raw data whose size is not a
/// multiple of the item size, data on a void/nested element or children on a non-nested one; a v4
/// string-table code that is in neither the message's local table nor the standard table; explicit
/// v4_flags that would drop a field holding data (MULTIPLE_ENTRIES clear with ≠ 1 entry, META_INFO
/// clear with MetaData/MessageID/MessageResID set, STRING_TABLE, EXTENDED or PRIORITY clear while the
/// field is set). ROUTING_INFO / ENDPOINT_INFO clear is never an error: those fields are omitted.
Result<void> encode_message(const Message& message, std::vector<std::byte>& out);

/// The same into a GatherBuffer: element payloads of GatherBuffer::kSpliceMinBytes and more that have
/// an owner are spliced in, not copied (the buffer keeps them alive until cleared).
Result<void> encode_message(const Message& message, GatherBuffer& out);

/// Encodes into a new buffer, ready to send or to decode with views into it.
Result<SharedBytes> encode_message(const Message& message);

/// Encodes `entry` on its own in format `version` (2 or 4), appending to `out`: the bytes it has inside
/// any message of that format (entries do not depend on their message, except for v4 string-table codes,
/// so a code must be in the standard table). An entry sent unchanged in many messages (a wire value or
/// event fanned out to many sessions, EncodedEntry) is encoded once this way and copied into each.
/// Errors: as encode_message for the entry.
Result<void> encode_entry(const MessageEntry& entry, std::uint16_t version, std::vector<std::byte>& out);

/// Encodes `message` in `message.version` with one entry already encoded by encode_entry in the same
/// format (`encoded_entry`); the result equals encode_message of the message with that entry.
/// Errors: InvalidArgument when `message.entries` is not empty; otherwise as encode_message.
Result<void> encode_message(const Message& message, std::span<const std::byte> encoded_entry,
                            std::vector<std::byte>& out);
/// The same into a GatherBuffer: the encoded entry is spliced in (not copied) when GatherBuffer::splices
/// it, and so are its large element payloads.
Result<void> encode_message(const Message& message, const SharedBytes& encoded_entry, GatherBuffer& out);

/// Encodes the message of `header`'s header and `entries` (kept where they are: a session's reply is
/// not moved into a Message to be sent); the result equals encode_message of the message with them.
/// Errors: InvalidArgument when `header.entries` is not empty; otherwise as encode_message.
Result<void> encode_message(const Message& header, std::span<const MessageEntry> entries, GatherBuffer& out);

}  // namespace rr
