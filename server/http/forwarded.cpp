#include "server/http/forwarded.hpp"

#include <cctype>

#include <boost/asio/ip/address_v6.hpp>

namespace rr::server::http {
namespace {

std::string_view trim(std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
    return s;
}

std::optional<boost::asio::ip::address> parse_address(std::string_view text) {
    text = trim(text);
    // "[::1]" and "[::1]:port" (RFC 7239 style), "1.2.3.4:port" as some proxies write them.
    if (!text.empty() && text.front() == '[') {
        auto close = text.find(']');
        if (close == std::string_view::npos) return std::nullopt;
        text = text.substr(1, close - 1);
    } else if (text.find(':') != std::string_view::npos && text.find(':') == text.rfind(':') &&
               text.find('.') != std::string_view::npos) {
        text = text.substr(0, text.find(':'));
    }
    boost::system::error_code ec;
    auto a = boost::asio::ip::make_address(std::string(text), ec);
    if (ec) return std::nullopt;
    return a;
}

boost::asio::ip::address unmapped(const boost::asio::ip::address& a) {
    if (a.is_v6() && a.to_v6().is_v4_mapped())
        return boost::asio::ip::make_address_v4(boost::asio::ip::v4_mapped, a.to_v6());
    return a;
}

bool in_network(const IpNetwork& n, const boost::asio::ip::address& address) {
    auto a = unmapped(address);
    if (a.is_v4() != n.base.is_v4()) return false;
    auto cmp = [&](const auto& x, const auto& y) {  // byte arrays
        unsigned bits = n.prefix_bits;
        for (std::size_t i = 0; i < x.size() && bits > 0; ++i, bits = bits >= 8 ? bits - 8 : 0) {
            unsigned mask = bits >= 8 ? 0xffu : (0xffu << (8 - bits)) & 0xffu;
            if ((x[i] & mask) != (y[i] & mask)) return false;
        }
        return true;
    };
    return a.is_v4() ? cmp(a.to_v4().to_bytes(), n.base.to_v4().to_bytes())
                     : cmp(a.to_v6().to_bytes(), n.base.to_v6().to_bytes());
}

}  // namespace

std::optional<IpNetwork> parse_ip_network(std::string_view text) {
    text = trim(text);
    auto slash = text.find('/');
    boost::system::error_code ec;
    auto base = boost::asio::ip::make_address(std::string(text.substr(0, slash)), ec);
    if (ec) return std::nullopt;
    base = unmapped(base);
    const unsigned max_bits = base.is_v4() ? 32 : 128;
    unsigned bits = max_bits;
    if (slash != std::string_view::npos) {
        auto digits = text.substr(slash + 1);
        if (digits.empty() || digits.size() > 3) return std::nullopt;
        bits = 0;
        for (char c : digits) {
            if (c < '0' || c > '9') return std::nullopt;
            bits = bits * 10 + static_cast<unsigned>(c - '0');
        }
        if (bits > max_bits) return std::nullopt;
    }
    return IpNetwork{base, bits};
}

bool in_networks(const std::vector<IpNetwork>& networks, const boost::asio::ip::address& address) {
    for (const auto& n : networks)
        if (in_network(n, address)) return true;
    return false;
}

ClientOrigin client_origin(const boost::asio::ip::address& peer, unsigned short peer_port, std::string_view forwarded_for,
                           std::string_view forwarded_proto, const std::vector<IpNetwork>& trusted) {
    ClientOrigin o;
    auto peer_text = [&] {
        auto a = unmapped(peer);
        return a.is_v6() ? "[" + a.to_string() + "]:" + std::to_string(peer_port)
                         : a.to_string() + ":" + std::to_string(peer_port);
    };
    if (!in_networks(trusted, peer)) {
        o.address = peer_text();
        return o;
    }
    o.forwarded = true;
    std::optional<boost::asio::ip::address> client;
    std::string_view rest = forwarded_for;
    while (!trim(rest).empty()) {
        auto comma = rest.rfind(',');
        auto entry = comma == std::string_view::npos ? rest : rest.substr(comma + 1);
        rest = comma == std::string_view::npos ? std::string_view{} : rest.substr(0, comma);
        auto a = parse_address(entry);
        if (!a) break;  // garbage: trust nothing further left
        client = unmapped(*a);
        if (!in_networks(trusted, *a)) break;
    }
    o.address = client ? client->to_string() : peer_text();
    auto proto = trim(forwarded_proto.substr(0, forwarded_proto.find(',')));
    auto lower = [](std::string_view s) {
        std::string t(s);
        for (auto& c : t) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
        return t;
    };
    auto p = lower(proto);
    if (p == "http" || p == "https") o.scheme = p;
    return o;
}

}  // namespace rr::server::http
