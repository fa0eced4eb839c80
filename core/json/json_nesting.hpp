// How deeply a JSON text nests, counted before parsing it: nlohmann-json recurses once per level, so
// a request or frame of a million '[' would exhaust the stack. Header-only (no dependency), for every
// place that parses JSON a peer sent (the JSON API, the Foxglove WebSocket).
#pragma once

#include <cstddef>
#include <string_view>

namespace rr::json_limits {

/// Whether `text` opens more than `limit` arrays/objects inside each other. Brackets inside strings
/// (escapes included) do not count; the text need not be valid JSON (the parser judges that after).
inline bool nests_deeper_than(std::string_view text, std::size_t limit) noexcept {
    std::size_t depth = 0;
    bool in_string = false, escaped = false;
    for (char c : text) {
        if (in_string) {
            if (escaped) escaped = false;
            else if (c == '\\') escaped = true;
            else if (c == '"') in_string = false;
            continue;
        }
        if (c == '"') in_string = true;
        else if (c == '[' || c == '{') {
            if (++depth > limit) return true;
        } else if ((c == ']' || c == '}') && depth > 0) {
            --depth;
        }
    }
    return false;
}

}  // namespace rr::json_limits
