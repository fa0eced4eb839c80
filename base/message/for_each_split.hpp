// Test helper (tests only): Beast-style "parsegrind" for RR messages. Feeds a byte stream to a fresh
// MessageStreamReader in two parts split at every offset (0 … size, so also in one piece), decodes
// every complete message, and hands each outcome to the test.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "base/message/message_stream_reader.hpp"

namespace rr::test {

/// Feeds `bytes` split at `at`, then decodes every complete message. Returns the messages in order,
/// or the first error (from framing or decoding). Bytes left in an unfinished message are an error
/// ("incomplete stream") so that a test of a whole stream cannot pass by yielding nothing.
inline Result<std::vector<Message>> decode_stream_split(std::span<const std::byte> bytes, std::size_t at,
                                                        const Limits& limits = {},
                                                        const DecodeContext* context = nullptr) {
    MessageStreamReader reader(limits);
    if (auto ok = reader.feed(bytes.first(at)); !ok) return ok.take_error();
    if (auto ok = reader.feed(bytes.subspan(at)); !ok) return ok.take_error();
    std::vector<Message> out;
    for (;;) {
        auto m = reader.take_message(context);
        if (!m) return m.take_error();
        if (!*m) break;
        out.push_back(std::move(**m));
    }
    if (reader.partial_bytes() != 0) return fail(MessageErrorType::ProtocolError, "incomplete stream");
    return out;
}

/// Calls `check(Result<std::vector<Message>>)` once per split offset. Use INFO in `check` for context;
/// the offset is given as the second argument.
template <class Check>
void for_each_split(std::span<const std::byte> bytes, Check&& check, const Limits& limits = {},
                    const DecodeContext* context = nullptr) {
    for (std::size_t at = 0; at <= bytes.size(); ++at) check(decode_stream_split(bytes, at, limits, context), at);
}

}  // namespace rr::test
