#include "base/names/object_path.hpp"

#include "base/names/service_path.hpp"

namespace rr {
namespace {

bool is_name_char(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_'; }

bool is_hex(char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f') || (c >= 'A' && c <= 'F'); }

// An index already in RR's service-path encoding: letters, digits, `_`, and `%hh` escapes.
bool is_encoded_index(std::string_view s) {
    for (std::size_t i = 0; i < s.size(); ++i) {
        if (is_name_char(s[i])) continue;
        if (s[i] == '%' && i + 2 < s.size() && is_hex(s[i + 1]) && is_hex(s[i + 2])) {
            i += 2;
            continue;
        }
        return false;
    }
    return true;
}

}  // namespace

std::string ObjectPathSegment::text() const { return has_index ? name + "[" + encoded_index + "]" : name; }

std::string ObjectPath::text() const {
    std::string out;
    for (const auto& s : segments) {
        if (!out.empty()) out += '.';
        out += s.text();
    }
    return out;
}

Result<ObjectPath> parse_object_path(std::string_view path, ObjectPathIndexes indexes) {
    const std::string quoted = "object path \"" + std::string(path) + "\"";
    auto bad = [&](const std::string& what) { return fail(MessageErrorType::InvalidArgument, quoted + what); };
    if (path.empty()) return bad(" is empty");
    ObjectPath out;
    std::size_t i = 0;
    while (i < path.size()) {
        const std::size_t start = i;
        while (i < path.size() && is_name_char(path[i])) ++i;
        if (i == start) return bad(": expected a member name at offset " + std::to_string(start));
        ObjectPathSegment segment;
        segment.name = std::string(path.substr(start, i - start));
        if (i < path.size() && path[i] == '[') {
            const auto close = path.find(']', i + 1);
            if (close == std::string_view::npos) return bad(": '[' without ']'");
            const auto index = path.substr(i + 1, close - i - 1);
            if (index.empty()) return bad(": empty index");
            segment.has_index = true;
            if (is_encoded_index(index)) {
                auto decoded = decode_service_path_index(index);
                if (!decoded) return bad(": " + decoded.error().message);
                segment.index = std::move(*decoded);
                segment.encoded_index = std::string(index);
            } else if (indexes == ObjectPathIndexes::encoded) {
                return bad(": index \"" + std::string(index) + "\" is not in service-path encoding (letters, digits, '_', %hh)");
            } else {
                segment.index = std::string(index);
                segment.encoded_index = encode_service_path_index(index);
            }
            i = close + 1;
        }
        out.segments.push_back(std::move(segment));
        if (i < path.size()) {
            if (path[i] != '.') return bad(": unexpected '" + std::string(1, path[i]) + "' at offset " + std::to_string(i));
            if (++i == path.size()) return bad(" ends with '.'");
        }
    }
    return out;
}

Result<std::string> normalize_object_path(std::string_view relative) {
    auto parsed = parse_object_path(relative);
    if (!parsed) return parsed.take_error();
    return parsed->text();
}

MemberPath split_member_path(std::string_view name) {
    int depth = 0;
    for (std::size_t i = name.size(); i-- > 0;) {
        if (name[i] == ']') ++depth;
        else if (name[i] == '[' && depth > 0) --depth;
        else if (name[i] == '.' && depth == 0) return {std::string(name.substr(0, i)), std::string(name.substr(i + 1))};
    }
    return {"", std::string(name)};
}

}  // namespace rr
