// Robot Raconteur connection URLs (standards draft/tcp_transport.md; CORE Transport.cpp ParseConnectionURL):
//   scheme://host[:port]/[path]?nodeid=…&nodename=…&service=…
// Schemes: rr+tcp, rrs+tcp (default port 48653), rr+ws, rrs+ws (80), rr+wss, rrs+wss (443),
// rr+local (no host/port; optional `user@localhost`), rr+usb, rr+pci, rr+bluetooth, and the legacy
// `tcp://host:port/{nodeid-or-nodename}/service` form.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "base/error/rr_error.hpp"
#include "base/names/node_id.hpp"

namespace rr {

struct ConnectionUrl {
    std::string scheme;      ///< lower case, e.g. "rr+tcp"
    std::string host;        ///< without IPv6 brackets; empty for rr+local
    std::uint16_t port = 0;  ///< explicit port or the scheme's default (0 where none applies)
    std::string path = "/";  ///< "/" unless given
    std::string user;        ///< rr+local `user@localhost`
    NodeID node_id;          ///< all-zero when absent
    std::string node_name;   ///< empty when absent
    std::string service;     ///< empty when absent

    bool is_tls() const noexcept { return scheme.rfind("rrs+", 0) == 0; }
    bool is_websocket() const noexcept;  ///< rr+ws, rr+wss, rrs+ws, rrs+wss
    bool is_secure_websocket() const noexcept { return scheme.ends_with("wss"); }

    /// Canonical text: `scheme://host:port/?nodeid=…&nodename=…&service=…` (only present parts); a
    /// legacy `tcp` URL keeps its own form `tcp://host:port/{node}/service`, so it parses back.
    std::string to_string() const;
};

/// Parses a connection URL. Errors: InvalidArgument naming the problem (unknown scheme, bad port,
/// bad nodeid, query part without '=', unterminated IPv6 bracket).
Result<ConnectionUrl> parse_connection_url(std::string_view url);

}  // namespace rr
