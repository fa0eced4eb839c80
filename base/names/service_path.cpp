#include "base/names/service_path.hpp"

#include "base/names/object_path.hpp"

namespace rr {
namespace {

bool is_alnum(char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9');
}

int hex_digit(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

}  // namespace

std::string encode_service_path_index(std::string_view index) {
    static constexpr char kHex[] = "0123456789abcdef";
    std::string out;
    out.reserve(index.size());
    for (char c : index) {
        if (is_alnum(c)) {
            out.push_back(c);
        } else {
            auto b = static_cast<unsigned char>(c);
            out.push_back('%');
            out.push_back(kHex[b >> 4]);
            out.push_back(kHex[b & 15]);
        }
    }
    return out;
}

std::string encode_service_path_index(std::int32_t index) { return encode_service_path_index(std::to_string(index)); }

Result<std::string> decode_service_path_index(std::string_view encoded) {
    std::string out;
    out.reserve(encoded.size());
    for (std::size_t i = 0; i < encoded.size(); ++i) {
        if (encoded[i] != '%') {
            out.push_back(encoded[i]);
            continue;
        }
        if (i + 2 >= encoded.size())
            return fail(MessageErrorType::InvalidArgument, "truncated %-escape in service path index");
        int hi = hex_digit(encoded[i + 1]), lo = hex_digit(encoded[i + 2]);
        if (hi < 0 || lo < 0) return fail(MessageErrorType::InvalidArgument, "bad %-escape in service path index");
        out.push_back(static_cast<char>(hi * 16 + lo));
        i += 2;
    }
    return out;
}

Result<std::vector<ServicePathSegment>> split_service_path(std::string_view path) {
    // A service path is an object path whose first segment is the service (object_path.hpp): one parser.
    auto parsed = parse_object_path(path, ObjectPathIndexes::encoded);
    if (!parsed) return parsed.take_error();
    std::vector<ServicePathSegment> segments;
    segments.reserve(parsed->segments.size());
    for (auto& s : parsed->segments) segments.push_back(ServicePathSegment{std::move(s.name), std::move(s.index), s.has_index});
    return segments;
}

std::string join_service_path(std::string_view parent, std::string_view member) {
    std::string s(parent);
    s += '.';
    s += member;
    return s;
}

std::string join_service_path(std::string_view parent, std::string_view member, std::string_view index) {
    std::string s = join_service_path(parent, member);
    s += '[';
    s += encode_service_path_index(index);
    s += ']';
    return s;
}

std::string_view service_name_of(std::string_view path) noexcept {
    auto dot = path.find('.');
    return dot == std::string_view::npos ? path : path.substr(0, dot);
}

std::string replace_service_name(std::string_view path, std::string_view new_service) {
    auto first = service_name_of(path);
    std::string s(new_service);
    s += path.substr(first.size());
    return s;
}

}  // namespace rr
