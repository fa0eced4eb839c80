// Encoding RR messages to bytes: message format v2 (wire.md §1) and v4 (wire.md §2).
//
// CONTRACT SKETCH — the codec implementation owns this file and may refine signatures, keeping the
// name encode_message.
#pragma once

#include <cstddef>
#include <vector>

#include "core/message/message.hpp"

namespace rr {

/// Encodes `message` in `message.version` (2 or 4), appending to `out`.
/// Errors: InvalidArgument (a v2 header string over 65535 bytes, more than 65535 entries, an element
/// whose data size is not a multiple of its item size, unknown version).
Result<void> encode_message(const Message& message, std::vector<std::byte>& out);

}  // namespace rr
