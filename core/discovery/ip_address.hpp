// IP address text and the address classes node discovery checks (wire.md §11.1): a discovery announce's
// URL host must be an IP literal, IPv6 ones link-local or site-local, IPv4 ones in the sender's /16.
// Sans-IO: parses text, no resolver.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace rr::discovery {

/// An IPv4 or IPv6 address (network byte order). IPv4 uses bytes[0..3].
struct IpAddress {
    bool v6 = false;
    std::array<std::uint8_t, 16> bytes{};

    static IpAddress v4_from(std::uint8_t a, std::uint8_t b, std::uint8_t c, std::uint8_t d) {
        IpAddress x;
        x.bytes = {a, b, c, d};
        return x;
    }

    bool is_loopback() const noexcept;    ///< 127.0.0.0/8, ::1
    bool is_link_local() const noexcept;  ///< IPv6 fe80::/10
    bool is_site_local() const noexcept;  ///< IPv6 fec0::/10
    bool is_v4_mapped() const noexcept;   ///< ::ffff:a.b.c.d

    /// Dotted IPv4, or the RFC 5952 IPv6 form (lower case, longest zero run as `::`), no brackets.
    std::string to_string() const;

    friend bool operator==(const IpAddress&, const IpAddress&) = default;
};

/// Parses `a.b.c.d` or an IPv6 literal (with `::`, an IPv4 tail, and an optional `%zone` suffix that is
/// ignored), without brackets. nullopt for anything else (host names included).
std::optional<IpAddress> parse_ip_address(std::string_view text);

}  // namespace rr::discovery
