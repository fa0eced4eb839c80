// Random identifiers a node or client picks for itself: NodeIDs (RFC 4122 version 4 UUIDs, as the
// official library makes them) and endpoint numbers (non-zero uint32, wire.md: 0 means "none").
// Thread-safe: each thread draws from its own generator seeded by std::random_device.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "base/names/node_id.hpp"

namespace rr::server {

/// A fresh version-4 NodeID (never the zero "any" NodeID).
NodeID random_node_id();

/// A fresh endpoint number, never 0.
std::uint32_t random_endpoint_id();

/// A fresh ServiceStateNonce: 16 characters of [A-Za-z0-9] (wire.md §11.1; CORE's form), never equal
/// to `previous`.
std::string random_service_state_nonce(std::string_view previous = {});

}  // namespace rr::server
