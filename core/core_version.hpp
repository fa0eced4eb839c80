// Version strings this implementation reports on the wire.
#pragma once

#include <string_view>

namespace rr {

/// Our own version.
std::string_view core_version() noexcept;

/// `clientversion` sent in ConnectClientCombined / GetServiceDesc / ObjectTypeName (wire.md §6.4):
/// the official library version whose protocol behaviour we follow.
inline constexpr std::string_view kProtocolClientVersion = "1.2.8";

}  // namespace rr
