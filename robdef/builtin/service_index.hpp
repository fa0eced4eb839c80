// The built-in `RobotRaconteurServiceIndex` service definition (robdef.md §13): registered on every
// node; discovery calls ServiceIndex.GetLocalNodeServices() on it to list a node's services.
#pragma once

#include <string_view>

namespace rr::robdef {

/// Definition text (our own layout: no stdver, as the official one, plain `end`, LF).
std::string_view service_index_robdef() noexcept;

/// Service name `RobotRaconteurServiceIndex` and its root object type.
inline constexpr std::string_view kServiceIndexServiceName = "RobotRaconteurServiceIndex";
inline constexpr std::string_view kServiceIndexObjectType = "RobotRaconteurServiceIndex.ServiceIndex";

}  // namespace rr::robdef
