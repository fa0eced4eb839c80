#include "core/discovery/ip_address.hpp"

#include <vector>

namespace rr::discovery {

namespace {

int hex_value(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

std::optional<std::array<std::uint8_t, 4>> parse_v4(std::string_view s) {
    std::array<std::uint8_t, 4> out{};
    std::size_t part = 0;
    std::size_t i = 0;
    while (part < 4) {
        if (i >= s.size() || s[i] < '0' || s[i] > '9') return std::nullopt;
        unsigned v = 0;
        std::size_t digits = 0;
        while (i < s.size() && s[i] >= '0' && s[i] <= '9') {
            v = v * 10 + static_cast<unsigned>(s[i] - '0');
            if (++digits > 3 || v > 255) return std::nullopt;
            ++i;
        }
        out[part++] = static_cast<std::uint8_t>(v);
        if (part < 4) {
            if (i >= s.size() || s[i] != '.') return std::nullopt;
            ++i;
        }
    }
    if (i != s.size()) return std::nullopt;
    return out;
}

std::optional<std::array<std::uint8_t, 16>> parse_v6(std::string_view s) {
    if (s.empty() || s.size() > 45) return std::nullopt;
    std::vector<std::uint16_t> head, tail;
    bool compressed = false;
    std::vector<std::uint16_t>* cur = &head;
    std::size_t i = 0;
    if (s.substr(0, 2) == "::") {
        compressed = true;
        cur = &tail;
        i = 2;
    } else if (s[0] == ':') {
        return std::nullopt;
    }
    std::optional<std::array<std::uint8_t, 4>> v4_tail;
    while (i < s.size()) {
        std::size_t end = s.find(':', i);
        std::string_view group = s.substr(i, end == std::string_view::npos ? std::string_view::npos : end - i);
        if (group.find('.') != std::string_view::npos) {
            if (end != std::string_view::npos) return std::nullopt;  // IPv4 only as the last part
            v4_tail = parse_v4(group);
            if (!v4_tail) return std::nullopt;
            i = s.size();
            break;
        }
        if (group.empty() || group.size() > 4) return std::nullopt;
        unsigned v = 0;
        for (char c : group) {
            int h = hex_value(c);
            if (h < 0) return std::nullopt;
            v = v * 16 + static_cast<unsigned>(h);
        }
        cur->push_back(static_cast<std::uint16_t>(v));
        if (end == std::string_view::npos) {
            i = s.size();
            break;
        }
        i = end + 1;
        if (i < s.size() && s[i] == ':') {
            if (compressed) return std::nullopt;  // a second "::"
            compressed = true;
            cur = &tail;
            ++i;
        } else if (i == s.size()) {
            return std::nullopt;  // trailing single ':'
        }
    }
    const std::size_t groups = head.size() + tail.size() + (v4_tail ? 2 : 0);
    if (compressed ? groups > 7 : groups != 8) return std::nullopt;
    std::array<std::uint8_t, 16> out{};
    std::size_t pos = 0;
    for (auto g : head) {
        out[pos++] = static_cast<std::uint8_t>(g >> 8);
        out[pos++] = static_cast<std::uint8_t>(g & 0xFF);
    }
    pos = 16 - tail.size() * 2 - (v4_tail ? 4 : 0);
    for (auto g : tail) {
        out[pos++] = static_cast<std::uint8_t>(g >> 8);
        out[pos++] = static_cast<std::uint8_t>(g & 0xFF);
    }
    if (v4_tail)
        for (auto b : *v4_tail) out[pos++] = b;
    return out;
}

}  // namespace

bool IpAddress::is_loopback() const noexcept {
    if (!v6) return bytes[0] == 127;
    for (std::size_t i = 0; i < 15; ++i)
        if (bytes[i] != 0) return false;
    return bytes[15] == 1;
}

bool IpAddress::is_link_local() const noexcept { return v6 && bytes[0] == 0xFE && (bytes[1] & 0xC0) == 0x80; }
bool IpAddress::is_site_local() const noexcept { return v6 && bytes[0] == 0xFE && (bytes[1] & 0xC0) == 0xC0; }

bool IpAddress::is_v4_mapped() const noexcept {
    if (!v6) return false;
    for (std::size_t i = 0; i < 10; ++i)
        if (bytes[i] != 0) return false;
    return bytes[10] == 0xFF && bytes[11] == 0xFF;
}

std::string IpAddress::to_string() const {
    if (!v6)
        return std::to_string(bytes[0]) + "." + std::to_string(bytes[1]) + "." + std::to_string(bytes[2]) + "." +
               std::to_string(bytes[3]);
    std::uint16_t g[8];
    for (std::size_t i = 0; i < 8; ++i) g[i] = static_cast<std::uint16_t>((bytes[2 * i] << 8) | bytes[2 * i + 1]);
    int best = -1, best_len = 0;
    for (int i = 0; i < 8;) {
        if (g[i] != 0) {
            ++i;
            continue;
        }
        int j = i;
        while (j < 8 && g[j] == 0) ++j;
        if (j - i > best_len && j - i >= 2) {
            best = i;
            best_len = j - i;
        }
        i = j;
    }
    static constexpr char kHex[] = "0123456789abcdef";
    std::string out;
    for (int i = 0; i < 8; ++i) {
        if (i == best) {
            out += "::";
            i += best_len - 1;
            continue;
        }
        if (!out.empty() && out.back() != ':') out += ':';
        bool started = false;
        for (int shift = 12; shift >= 0; shift -= 4) {
            unsigned d = (g[i] >> shift) & 0xF;
            if (d || started || shift == 0) {
                out += kHex[d];
                started = true;
            }
        }
    }
    return out;
}

std::optional<IpAddress> parse_ip_address(std::string_view text) {
    if (auto v4 = parse_v4(text)) {
        IpAddress a;
        a.bytes = {(*v4)[0], (*v4)[1], (*v4)[2], (*v4)[3]};
        return a;
    }
    if (auto pct = text.find('%'); pct != std::string_view::npos) {
        if (pct + 1 >= text.size()) return std::nullopt;
        text = text.substr(0, pct);
    }
    if (auto v6 = parse_v6(text)) {
        IpAddress a;
        a.v6 = true;
        a.bytes = *v6;
        return a;
    }
    return std::nullopt;
}

}  // namespace rr::discovery
