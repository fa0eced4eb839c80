// Node discovery datagrams (wire.md §11.1; official CORE TcpTransport.cpp IPNodeDiscovery and
// Discovery.cpp NodeAnnouncePacketReceived): UDP port 48653, UTF-8 text, lines ending in '\n'.
//
//   announce:  "Robot Raconteur Node Discovery Packet\n"
//              "{nodeid}[,NodeName]\n"
//              "<scheme>://<ip>:<port>/?nodeid=<id>&service=RobotRaconteurServiceIndex\n"
//              ["ServiceStateNonce: <16 alphanumerics>\n"]          (dropped when the packet > 2048 bytes)
//   request:   "Robot Raconteur Discovery Request Packet\n"
//              "{request uuid}\n"
//
// Receiving follows CORE's checks in order; a packet that fails one is rejected with a reason (and
// counted by the caller), never partly used. Sans-IO: the datagram's source address is passed in.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>

#include "core/discovery/ip_address.hpp"
#include "base/error/rr_error.hpp"
#include "base/names/node_id.hpp"

namespace rr::discovery {

inline constexpr std::uint16_t kDiscoveryPort = 48653;
inline constexpr std::string_view kAnnounceMagic = "Robot Raconteur Node Discovery Packet";
inline constexpr std::string_view kRequestMagic = "Robot Raconteur Discovery Request Packet";
inline constexpr std::string_view kServiceIndexName = "RobotRaconteurServiceIndex";
/// Receive buffer per datagram in CORE; longer datagrams are rejected here.
inline constexpr std::size_t kMaxDatagram = 8192;
/// An announce with its nonce line must fit in this many bytes, else the nonce line is left out.
inline constexpr std::size_t kMaxAnnounceWithNonce = 2048;
inline constexpr std::size_t kMaxUrlLength = 256;
inline constexpr std::size_t kMaxNodeNameLength = 128;
/// A ServiceStateNonce is used only when shorter than this.
inline constexpr std::size_t kMaxNonceLength = 32;

/// IPNodeDiscoveryFlags (CORE TcpTransport.h): which groups a node announces to and listens on.
enum DiscoveryFlags : std::uint32_t {
    kNodeLocal = 0x1,      ///< IPv6 FF01::BA86
    kLinkLocal = 0x2,      ///< IPv6 FF02::BA86 (the default)
    kSiteLocal = 0x4,      ///< IPv6 FF05::BA86
    kIpv4Broadcast = 0x8,  ///< 255.255.255.255
};

/// A received announce, validated.
struct Announce {
    NodeID node_id;
    std::string node_name;  ///< "" when absent or longer than 128 bytes (CORE clears it)
    std::string url;        ///< the one connection URL of the packet (≤ 256 bytes, nodeid = node_id)
    std::string service_state_nonce;  ///< "" when absent (or ≥ 32 bytes)
};

/// A received request: the requester's request UUID.
struct Request {
    NodeID request_id;
};

/// Why a datagram was not used.
enum class Reject : std::uint8_t {
    not_discovery,      ///< neither magic
    oversized,          ///< more than kMaxDatagram bytes
    truncated,          ///< fewer than three '\n'-separated fields
    bad_node_id,        ///< the NodeID field does not parse (or is all-zero)
    url_too_long,       ///< URL over 256 bytes
    bad_url,            ///< URL does not parse
    not_ip_literal,     ///< URL host is not an IP address
    family_mismatch,    ///< URL address family differs from the datagram's source
    not_link_local,     ///< IPv6 URL address neither link-local nor site-local
    subnet_mismatch,    ///< IPv4 URL address not in the sender's /16
    node_id_mismatch,   ///< URL's nodeid differs from the packet's NodeID
    own_packet,         ///< our own NodeID / request id
};
std::string_view reject_name(Reject r) noexcept;

/// Where a datagram came from (the receiver's socket tells).
struct PacketSource {
    IpAddress address;
};

using Packet = std::variant<Announce, Request>;

/// Parses and validates one datagram. `own_node_id` / `own_request_id` are ignored when all-zero.
/// Returns the packet or why it was rejected.
std::variant<Packet, Reject> parse_packet(std::string_view datagram, const PacketSource& source,
                                          const NodeID& own_node_id, const NodeID& own_request_id);

/// Text of our announce for one listening address: `scheme://ip:port/?nodeid=…&service=RobotRaconteurServiceIndex`
/// (IPv6 in brackets, no zone) plus the nonce line when the packet stays within 2048 bytes.
std::string format_announce(const NodeID& node_id, std::string_view node_name, std::string_view scheme,
                            const IpAddress& address, std::uint16_t port, std::string_view service_state_nonce);

/// Text of a request with our request UUID.
std::string format_request(const NodeID& request_id);

/// A fresh ServiceStateNonce: 16 characters of [a-zA-Z0-9] drawn from `random` (16 bytes or more).
std::string make_service_state_nonce(std::span<const std::uint8_t> random);

}  // namespace rr::discovery
