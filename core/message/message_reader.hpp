// Decoding RR messages from bytes: message format v2 (wire.md §1) and v4 (wire.md §2).
//
// CONTRACT SKETCH — the codec implementation owns this file and may refine signatures, keeping the
// names decode_message / MessageStreamReader.
//
// Errors: ProtocolError (bad magic, unknown version, sizes that do not add up, unknown data type,
// unknown string-table code), BufferLimitViolation (a size over Limits). Never UB, crash or hang.
// Memory: nothing is reserved before the length it depends on has been checked against the bytes
// present and Limits.
#pragma once

#include <optional>
#include <span>

#include "core/codec/limits.hpp"
#include "core/codec/shared_bytes.hpp"
#include "core/message/message.hpp"

namespace rr {

/// What a v4 decoder needs from the connection: values for header fields the sender omitted
/// (routing/endpoint info, wire.md §2.3) and which string tables are in force (wire.md §2.6).
struct DecodeContext {
    NodeID local_node_id;
    NodeID remote_node_id;
    std::uint32_t local_endpoint = 0;
    std::uint32_t remote_endpoint = 0;
};

/// Decodes one complete message held in `buffer` (exactly one message: MessageSize == buffer size).
/// Element payloads in the result are views into `buffer`: no copy.
Result<Message> decode_message(SharedBytes buffer, const Limits& limits = {}, const DecodeContext* context = nullptr);

}  // namespace rr
