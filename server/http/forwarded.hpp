// Who a request came from behind reverse proxies (docs/deployment.md, "Trusted proxies"):
// X-Forwarded-For and X-Forwarded-Proto are believed only when the TCP peer is a configured trusted
// proxy; anyone else could write them. Used for logs and the same-origin check of the HTTP side.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <boost/asio/ip/address.hpp>

namespace rr::server::http {

/// An address range: `base` with the first `prefix_bits` bits significant (an address alone = all bits).
struct IpNetwork {
    boost::asio::ip::address base;
    unsigned prefix_bits = 0;
};

/// Parses "127.0.0.1", "10.0.0.0/8", "::1", "fd00::/8". nullopt for anything else (a host name, a
/// prefix longer than the address, bits set below the prefix are allowed and ignored).
std::optional<IpNetwork> parse_ip_network(std::string_view text);

/// True when `address` is inside one of `networks` (IPv4-mapped IPv6 addresses match IPv4 ranges).
bool in_networks(const std::vector<IpNetwork>& networks, const boost::asio::ip::address& address);

struct ClientOrigin {
    std::string address;  ///< the client's address (no port when it came from X-Forwarded-For)
    std::string scheme;   ///< "http" or "https" as the client used it; "" when not known (no trusted proxy)
    bool forwarded = false;  ///< true when the peer is a trusted proxy and its headers were used
};

/// The client behind `peer` (the TCP peer, "address" form without port; `peer_port` for the text when
/// the peer is the client). With `peer` in `trusted`: X-Forwarded-For is walked from the right (the
/// entry the nearest proxy added) past further trusted proxies; the first untrusted entry is the client
/// (all trusted: the leftmost). Entries that are not IP addresses end the walk there (the client is the
/// last good entry seen, else the peer). X-Forwarded-Proto: its first value when "http" or "https".
/// Without a trusted peer both headers are ignored.
ClientOrigin client_origin(const boost::asio::ip::address& peer, unsigned short peer_port, std::string_view forwarded_for,
                           std::string_view forwarded_proto, const std::vector<IpNetwork>& trusted);

}  // namespace rr::server::http
