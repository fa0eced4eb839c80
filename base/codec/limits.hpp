// Decoder limits (STYLE: one struct, each field with unit, default and the error it produces).
// Every length field read from the wire is checked against the bytes present and these limits
// before anything is allocated.
#pragma once

#include <cstddef>
#include <cstdint>

namespace rr {

struct Limits {
    /// Largest whole message accepted, bytes (MessageSize). Default 12 MiB, as CORE (wire.md §13).
    /// Exceeding it: BufferLimitViolation.
    std::size_t max_message_size = 12u * 1024u * 1024u;
    /// Largest message before a client session exists, bytes (wire.md §6.4). Enforced by transports.
    std::size_t max_pre_session_message_size = 512u * 1024u;
    /// Entries per message. Default 65535 (v2 field width). Exceeding: BufferLimitViolation.
    std::size_t max_entries = 65535;
    /// Elements in one message counted at every nesting level. Exceeding: BufferLimitViolation.
    std::size_t max_elements = 1u << 20;
    /// Nesting depth of elements inside an entry (1 = flat). Exceeding: ProtocolError.
    std::size_t max_nesting_depth = 64;
};

}  // namespace rr
