#include "base/names/connection_url.hpp"

#include <array>
#include <charconv>

namespace rr {
namespace {

struct SchemeInfo {
    std::string_view scheme;
    std::uint16_t default_port;
};

constexpr std::array kSchemes{
    SchemeInfo{"rr+tcp", 48653},  SchemeInfo{"rrs+tcp", 48653}, SchemeInfo{"tcp", 48653},
    SchemeInfo{"rr+ws", 80},      SchemeInfo{"rrs+ws", 80},     SchemeInfo{"rr+wss", 443},
    SchemeInfo{"rrs+wss", 443},   SchemeInfo{"rr+local", 0},    SchemeInfo{"rr+usb", 0},
    SchemeInfo{"rr+pci", 0},      SchemeInfo{"rr+bluetooth", 0},
};

Unexpected bad(std::string_view url, std::string_view why) {
    return fail(MessageErrorType::InvalidArgument,
                "invalid connection URL \"" + std::string(url) + "\": " + std::string(why));
}

char lower(char c) { return (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c; }

int hex_digit(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    c = lower(c);
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    return -1;
}

// Decodes %hh escapes in a query value; a malformed escape is kept verbatim.
std::string percent_decode(std::string_view s) {
    std::string out;
    out.reserve(s.size());
    for (std::size_t i = 0; i < s.size(); ++i) {
        if (s[i] == '%' && i + 2 < s.size()) {
            int hi = hex_digit(s[i + 1]), lo = hex_digit(s[i + 2]);
            if (hi >= 0 && lo >= 0) {
                out.push_back(static_cast<char>(hi * 16 + lo));
                i += 2;
                continue;
            }
        }
        out.push_back(s[i]);
    }
    return out;
}

Result<std::uint16_t> parse_port(std::string_view url, std::string_view text) {
    unsigned value = 0;
    auto [p, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (text.empty() || ec != std::errc() || p != text.data() + text.size() || value == 0 || value > 65535)
        return bad(url, "bad port \"" + std::string(text) + "\"");
    return static_cast<std::uint16_t>(value);
}

bool is_word_char(char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
}

// Host rules of CORE's ParseConnectionURL: `[` hex digits and colons, optionally `%zone` `]` (IPv6), or
// no brackets, colons, slashes, question marks or blanks. We also refuse '@' (the user is split off
// before) and control characters.
bool valid_ipv6_host(std::string_view h) {
    auto pct = h.find('%');
    auto addr = h.substr(0, pct);
    if (addr.empty()) return false;
    for (char c : addr)
        if (c != ':' && hex_digit(c) < 0) return false;
    if (pct != std::string_view::npos)
        for (char c : h.substr(pct + 1))
            if (!is_word_char(c)) return false;
    return true;
}

bool valid_plain_host(std::string_view h) {
    for (char c : h) {
        auto u = static_cast<unsigned char>(c);
        if (u <= 0x20 || u == 0x7f || c == '[' || c == ']' || c == ':' || c == '/' || c == '?' || c == '@') return false;
    }
    return true;
}

// Query values are written with %hh for what would end or split them when read back.
std::string encode_query_value(std::string_view v) {
    static constexpr char kHex[] = "0123456789abcdef";
    std::string out;
    for (char c : v) {
        auto u = static_cast<unsigned char>(c);
        if (c == '%' || c == '&' || c == '#' || u <= 0x20 || u >= 0x7f) {
            out += '%';
            out += kHex[u >> 4];
            out += kHex[u & 15];
        } else {
            out += c;
        }
    }
    return out;
}

}  // namespace

bool ConnectionUrl::is_websocket() const noexcept {
    return scheme == "rr+ws" || scheme == "rr+wss" || scheme == "rrs+ws" || scheme == "rrs+wss";
}

std::string ConnectionUrl::to_string() const {
    std::string s = scheme + "://";
    if (!user.empty()) s += user + "@";
    if (host.find(':') != std::string::npos)
        s += "[" + host + "]";
    else
        s += host;
    if (port) s += ":" + std::to_string(port);
    char sep = '?';
    auto add = [&](std::string_view k, const std::string& v) {
        s += sep;
        s += k;
        s += '=';
        s += encode_query_value(v);
        sep = '&';
    };
    if (scheme == "tcp") {
        // Legacy form: tcp://host:port/{node}/service. What the path cannot hold goes in the query,
        // which is read after the path.
        const bool id = !node_id.is_any();
        const bool name_in_path =
            !id && node_name.find_first_of("/?{") == std::string::npos && !NodeID::parse(node_name);
        // The parser keeps only the path's second segment, so a service with '/' goes in the query.
        const bool service_in_path = service.find_first_of("?/") == std::string::npos;
        s += "/" + (id ? node_id.to_braced_string() : name_in_path ? node_name : std::string()) + "/" +
             (service_in_path ? service : std::string());
        if (!name_in_path && !node_name.empty()) add("nodename", node_name);
        if (!service_in_path) add("service", service);
        return s;
    }
    s += path.empty() ? "/" : path;
    if (!node_id.is_any()) add("nodeid", node_id.to_string());
    if (!node_name.empty()) add("nodename", node_name);
    if (!service.empty()) add("service", service);
    return s;
}

Result<ConnectionUrl> parse_connection_url(std::string_view url) {
    ConnectionUrl out;
    auto sep = url.find("://");
    if (sep == std::string_view::npos) return bad(url, "missing \"://\"");
    for (char c : url.substr(0, sep)) out.scheme.push_back(lower(c));
    const SchemeInfo* info = nullptr;
    for (const auto& s : kSchemes)
        if (s.scheme == out.scheme) info = &s;
    if (!info) return bad(url, "unknown scheme \"" + out.scheme + "\"");

    std::string_view rest = url.substr(sep + 3);
    std::string_view query;
    if (auto q = rest.find('?'); q != std::string_view::npos) {
        query = rest.substr(q + 1);
        rest = rest.substr(0, q);
    }
    std::string_view authority = rest;
    std::string_view path;
    if (auto slash = rest.find('/'); slash != std::string_view::npos) {
        authority = rest.substr(0, slash);
        path = rest.substr(slash);
    }
    if (auto at = authority.find('@'); at != std::string_view::npos) {
        out.user = std::string(authority.substr(0, at));
        authority = authority.substr(at + 1);
        if (out.user.empty()) return bad(url, "empty user before '@'");
    }
    std::string_view port_text;
    if (!authority.empty() && authority.front() == '[') {
        auto close = authority.find(']');
        if (close == std::string_view::npos) return bad(url, "unterminated IPv6 address");
        out.host = std::string(authority.substr(1, close - 1));
        if (!valid_ipv6_host(out.host)) return bad(url, "bad IPv6 address \"" + out.host + "\"");
        auto after = authority.substr(close + 1);
        if (!after.empty()) {
            if (after.front() != ':') return bad(url, "junk after IPv6 address");
            port_text = after.substr(1);
        }
    } else {
        auto colon = authority.rfind(':');
        out.host = std::string(authority.substr(0, colon));
        if (colon != std::string_view::npos) port_text = authority.substr(colon + 1);
        if (!valid_plain_host(out.host)) return bad(url, "bad host \"" + out.host + "\"");
    }
    if (!port_text.empty()) {
        auto port = parse_port(url, port_text);
        if (!port) return port.take_error();
        out.port = *port;
    } else {
        out.port = info->default_port;
    }
    if (out.scheme == "rr+local" && (!port_text.empty())) return bad(url, "rr+local takes no port");

    out.path = path.empty() ? std::string("/") : std::string(path);

    // Legacy form: tcp://host:port/{nodeid-or-nodename}/service
    if (out.scheme == "tcp") {
        std::string_view p = path;
        if (!p.empty() && p.front() == '/') p.remove_prefix(1);
        auto slash = p.find('/');
        if (slash == std::string_view::npos) return bad(url, "legacy tcp:// URL needs /{node}/service");
        auto node = p.substr(0, slash);
        auto service = p.substr(slash + 1);
        service = service.substr(0, service.find('/'));  // CORE uses the second segment only
        out.service = std::string(service);  // may come from ?service= instead (checked below)
        if (node.find('{') != std::string_view::npos) {  // as CORE: braces mean a NodeID, else a NodeName
            auto id = NodeID::parse(node);
            if (!id) return bad(url, "bad nodeid \"" + std::string(node) + "\"");
            out.node_id = *id;
        } else {
            out.node_name = std::string(node);
        }
        out.path = "/";
    }

    while (!query.empty()) {
        auto amp = query.find('&');
        auto part = query.substr(0, amp);
        query = amp == std::string_view::npos ? std::string_view{} : query.substr(amp + 1);
        if (part.empty()) continue;
        auto eq = part.find('=');
        if (eq == std::string_view::npos) return bad(url, "query part \"" + std::string(part) + "\" has no '='");
        auto key = part.substr(0, eq);
        auto value = percent_decode(part.substr(eq + 1));
        if (key == "nodeid") {
            auto id = NodeID::parse(value);
            if (!id) return bad(url, "bad nodeid \"" + value + "\"");
            out.node_id = *id;
        } else if (key == "nodename") {
            out.node_name = value;
        } else if (key == "service") {
            out.service = value;
        }
        // Other keys are ignored, as CORE does for unknown query parts it does not use.
    }
    if (out.scheme == "tcp" && out.service.empty()) return bad(url, "legacy tcp:// URL needs /{node}/service");
    return out;
}

}  // namespace rr
