// Errors of the rr+usb host transport, as Boost error codes (what a stream operation completes with;
// StreamPump turns ec.message() into the RR ConnectionError that fails pending requests) and as RR
// errors (what connect and enumerate report).
#pragma once

#include <cstdint>
#include <string>

#include <boost/system/error_code.hpp>

#include "base/error/rr_error.hpp"

namespace rr::server::usb {

enum class usb_errc {
    device_unplugged = 1,   ///< the USB device went away (unplugged, reset, powered off)
    device_io_error,        ///< a transfer failed (stall, overflow, I/O error)
    protocol_error,         ///< the device broke the rr+usb framing; the link was dropped
    link_closed,            ///< the host closed the link (shutdown)
    stream_refused,         ///< CONNECT_STREAM answered a negative id
};

const boost::system::error_category& usb_category() noexcept;
inline boost::system::error_code make_error_code(usb_errc e) noexcept { return {static_cast<int>(e), usb_category()}; }

/// Text of a libusb error code (libusb_strerror), e.g. "Access denied (insufficient permissions)".
std::string libusb_error_text(int libusb_error);

/// The udev rule shipped with the gateway, and the hint every permission error carries.
inline constexpr const char* kUdevRuleFile = "gateway-config/70-robotraconteur-usb.rules";
/// "no permission to open USB device VID:PID at PATH: install …" (SystemResourcePermissionDenied).
RRError permission_error(std::uint16_t vendor_id, std::uint16_t product_id, const std::string& device_path);

}  // namespace rr::server::usb

namespace boost::system {
template <>
struct is_error_code_enum<rr::server::usb::usb_errc> : std::true_type {};
}  // namespace boost::system
