#include "base/names/node_id.hpp"

namespace rr {
namespace {

int hex_value(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

}  // namespace

Result<NodeID> NodeID::parse(std::string_view text) {
    if (text.size() >= 2 && text.front() == '{' && text.back() == '}') text = text.substr(1, text.size() - 2);
    const bool dashed = text.size() == 36;
    if (!dashed && text.size() != 32) return fail(MessageErrorType::InvalidArgument, "invalid NodeID text");
    Bytes out{};
    std::size_t nibble = 0;
    for (std::size_t i = 0; i < text.size(); ++i) {
        if (dashed && (i == 8 || i == 13 || i == 18 || i == 23)) {
            if (text[i] != '-') return fail(MessageErrorType::InvalidArgument, "invalid NodeID text");
            continue;
        }
        int v = hex_value(text[i]);
        if (v < 0) return fail(MessageErrorType::InvalidArgument, "invalid NodeID text");
        auto& b = out[nibble / 2];
        b = static_cast<std::byte>((static_cast<unsigned>(b) << 4) | static_cast<unsigned>(v));
        ++nibble;
    }
    return NodeID(out);
}

std::string NodeID::to_string() const {
    static constexpr char kHex[] = "0123456789abcdef";
    std::string s;
    s.reserve(36);
    for (std::size_t i = 0; i < 16; ++i) {
        if (i == 4 || i == 6 || i == 8 || i == 10) s.push_back('-');
        auto v = static_cast<unsigned>(bytes_[i]);
        s.push_back(kHex[v >> 4]);
        s.push_back(kHex[v & 15]);
    }
    return s;
}

std::string NodeID::to_braced_string() const {
    // Appended, not "{" + s + "}": GCC 12 at -O2 warns (-Wrestrict) on the latter (a false positive).
    std::string s(1, '{');
    s += to_string();
    s += '}';
    return s;
}

}  // namespace rr
