#include "core/discovery/discovery_packet.hpp"

#include <vector>

#include "base/names/connection_url.hpp"

namespace rr::discovery {

namespace {

// boost::split on '\n' as CORE does: n separators give n+1 fields (a trailing '\n' gives an empty last one).
std::vector<std::string_view> split(std::string_view s, char sep) {
    std::vector<std::string_view> out;
    std::size_t start = 0;
    for (;;) {
        auto end = s.find(sep, start);
        if (end == std::string_view::npos) {
            out.push_back(s.substr(start));
            return out;
        }
        out.push_back(s.substr(start, end - start));
        start = end + 1;
    }
}

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f'; }

std::string_view trim(std::string_view s) {
    while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
    while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
    return s;
}

bool is_word(char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
}

// CORE's attribute line rule: ^\s*([\w+\.\-]+)\s*:\s*(.*)\s*$ on the trimmed line.
bool parse_attribute(std::string_view line, std::string_view& name, std::string_view& value) {
    std::size_t i = 0;
    while (i < line.size() && (is_word(line[i]) || line[i] == '+' || line[i] == '.' || line[i] == '-')) ++i;
    if (i == 0) return false;
    name = line.substr(0, i);
    std::size_t j = i;
    while (j < line.size() && is_space(line[j])) ++j;
    if (j >= line.size() || line[j] != ':') return false;
    value = trim(line.substr(j + 1));
    return true;
}

std::optional<Reject> check_url_address(const ConnectionUrl& url, const PacketSource& source) {
    auto addr = parse_ip_address(url.host);
    if (!addr) return Reject::not_ip_literal;
    if (addr->is_loopback()) return std::nullopt;
    IpAddress from = source.address;
    if (from.is_v4_mapped()) {  // a dual-stack socket reports IPv4 senders as ::ffff:a.b.c.d
        from = IpAddress::v4_from(from.bytes[12], from.bytes[13], from.bytes[14], from.bytes[15]);
    }
    if (addr->v6 != from.v6) return Reject::family_mismatch;
    if (addr->v6 && !addr->is_link_local() && !addr->is_site_local()) return Reject::not_link_local;
    if (!addr->v6 && (addr->bytes[0] != from.bytes[0] || addr->bytes[1] != from.bytes[1]))
        return Reject::subnet_mismatch;
    return std::nullopt;
}

}  // namespace

std::string_view reject_name(Reject r) noexcept {
    switch (r) {
        case Reject::not_discovery: return "not_discovery";
        case Reject::oversized: return "oversized";
        case Reject::truncated: return "truncated";
        case Reject::bad_node_id: return "bad_node_id";
        case Reject::url_too_long: return "url_too_long";
        case Reject::bad_url: return "bad_url";
        case Reject::not_ip_literal: return "not_ip_literal";
        case Reject::family_mismatch: return "family_mismatch";
        case Reject::not_link_local: return "not_link_local";
        case Reject::subnet_mismatch: return "subnet_mismatch";
        case Reject::node_id_mismatch: return "node_id_mismatch";
        case Reject::own_packet: return "own_packet";
    }
    return "unknown";
}

std::variant<Packet, Reject> parse_packet(std::string_view datagram, const PacketSource& source,
                                          const NodeID& own_node_id, const NodeID& own_request_id) {
    if (datagram.size() > kMaxDatagram) return Reject::oversized;
    const bool announce = datagram.substr(0, kAnnounceMagic.size()) == kAnnounceMagic;
    const bool request = !announce && datagram.substr(0, kRequestMagic.size()) == kRequestMagic;
    if (!announce && !request) return Reject::not_discovery;

    auto lines = split(datagram, '\n');
    if (lines.size() < 3) return Reject::truncated;
    auto id_fields = split(lines[1], ',');
    auto id = NodeID::parse(id_fields[0]);
    if (!id) return Reject::bad_node_id;

    if (request) {
        if (!own_request_id.is_any() && *id == own_request_id) return Reject::own_packet;
        return Packet{Request{*id}};
    }

    std::string_view url = lines[2];
    if (url.size() > kMaxUrlLength) return Reject::url_too_long;
    auto parsed = parse_connection_url(url);
    if (!parsed) return Reject::bad_url;
    if (auto r = check_url_address(*parsed, source)) return *r;
    if (parsed->node_id != *id) return Reject::node_id_mismatch;
    if (id->is_any()) return Reject::bad_node_id;  // CORE's NodeDetected ignores the all-zero NodeID
    if (!own_node_id.is_any() && *id == own_node_id) return Reject::own_packet;

    Announce a;
    a.node_id = *id;
    if (id_fields.size() > 1 && id_fields[1].size() <= kMaxNodeNameLength) a.node_name = std::string(id_fields[1]);
    a.url = std::string(url);
    for (std::size_t i = 3; i < lines.size(); ++i) {
        auto line = trim(lines[i]);
        if (line.empty()) continue;
        std::string_view name, value;
        if (!parse_attribute(line, name, value)) continue;
        if (name == "ServiceStateNonce" && value.size() < kMaxNonceLength) a.service_state_nonce = std::string(value);
    }
    return Packet{std::move(a)};
}

std::string format_announce(const NodeID& node_id, std::string_view node_name, std::string_view scheme,
                            const IpAddress& address, std::uint16_t port, std::string_view service_state_nonce) {
    std::string p;
    p.reserve(256);
    p += kAnnounceMagic;
    p += '\n';
    p += node_id.to_braced_string();
    if (!node_name.empty()) {
        p += ',';
        p += node_name;
    }
    p += '\n';
    p += scheme;
    p += "://";
    if (address.v6) {
        p += '[';
        p += address.to_string();
        p += ']';
    } else {
        p += address.to_string();
    }
    p += ':';
    p += std::to_string(port);
    p += "/?nodeid=";
    p += node_id.to_string();
    p += "&service=";
    p += kServiceIndexName;
    p += '\n';
    const std::size_t nonce_line = 19 + service_state_nonce.size() + 1;  // "ServiceStateNonce: " + nonce + "\n"
    if (p.size() + nonce_line <= kMaxAnnounceWithNonce) {
        p += "ServiceStateNonce: ";
        p += service_state_nonce;
        p += '\n';
    }
    return p;
}

std::string format_request(const NodeID& request_id) {
    std::string p(kRequestMagic);
    p += '\n';
    p += request_id.to_braced_string();
    p += '\n';
    return p;
}

std::string make_service_state_nonce(std::span<const std::uint8_t> random) {
    static constexpr std::string_view kChars = "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789";
    std::string out;
    out.reserve(16);
    for (std::size_t i = 0; i < 16; ++i) {
        std::uint8_t b = i < random.size() ? random[i] : static_cast<std::uint8_t>(i * 37);
        out += kChars[b % kChars.size()];
    }
    return out;
}

}  // namespace rr::discovery
