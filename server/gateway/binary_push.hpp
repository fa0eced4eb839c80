// Binary pushes of the JSON WebSocket (docs/json-api.md "Binary pushes"): a subscription made with
// "binary": true gets each value whose JSON has numeric arrays as one binary WebSocket message
//
//   0        "RRJB"
//   4        uint32 LE: J, the length of the JSON text
//   8        the push as JSON text (UTF-8), each numeric array replaced by
//            {"$binary": i, "type": "<RR type>", "length": items, "offset": bytes} (BinaryArrays)
//   8+J      zero bytes up to B, the next multiple of 8
//   B        the arrays' little-endian bytes, array i at B + offset, each padded to a multiple of 8
//
// so a browser makes a typed array over the message (new Float64Array(buffer, B + offset, length))
// without copying or parsing numbers; values without numeric arrays stay text messages.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "base/codec/shared_bytes.hpp"
#include "base/error/rr_error.hpp"

namespace rr::server::gateway {

inline constexpr std::string_view kBinaryPushMagic = "RRJB";

/// The message for `json_text` (a push with "$binary" references) and the arrays it refers to:
/// binary_push_head(json_text) followed by binary_push_arrays(blobs).
std::string binary_push_message(std::string_view json_text, const std::vector<SharedBytes>& blobs);
/// The message up to the arrays: magic, length, the JSON text, zero padding to a multiple of 8.
std::string binary_push_head(std::string_view json_text);
/// The arrays' part: each array's bytes padded to a multiple of 8, in order (the same for every
/// subscriber of a value, whose pushes differ only in the head).
std::string binary_push_arrays(const std::vector<SharedBytes>& blobs);

/// The two parts of a binary message: the JSON text, and the arrays (starting at B, so a reference's
/// `offset` counts from arrays.data()). Views into `message`. Errors: ProtocolError (no RRJB header,
/// lengths past the message).
struct BinaryPushParts {
    std::string_view json_text;
    std::string_view arrays;
};
Result<BinaryPushParts> split_binary_push(std::string_view message);

/// The push a binary message carries, each "$binary" reference replaced by the array's JSON numbers
/// (what the text form of the same push holds): the reference decoder, for tests and tools.
/// Errors: ProtocolError for a message that is not one (magic, lengths, a reference outside the
/// message, an unknown type, bad JSON).
Result<nlohmann::json> decode_binary_push(std::string_view message);

}  // namespace rr::server::gateway
