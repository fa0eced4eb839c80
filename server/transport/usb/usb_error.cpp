#include "server/transport/usb/usb_error.hpp"

#include <cstdio>

#include <libusb.h>

namespace rr::server::usb {

namespace {

class UsbCategory final : public boost::system::error_category {
public:
    const char* name() const noexcept override { return "rr.usb"; }
    std::string message(int ev) const override {
        switch (static_cast<usb_errc>(ev)) {
            case usb_errc::device_unplugged: return "USB device was unplugged";
            case usb_errc::device_io_error: return "USB transfer failed";
            case usb_errc::protocol_error: return "USB device broke the rr+usb protocol";
            case usb_errc::link_closed: return "USB link closed";
            case usb_errc::stream_refused: return "USB device refused the stream";
        }
        return "USB error";
    }
};

std::string hex4(std::uint16_t v) {
    char b[8];
    std::snprintf(b, sizeof b, "%04x", v);
    return b;
}

}  // namespace

const boost::system::error_category& usb_category() noexcept {
    static const UsbCategory c;
    return c;
}

std::string libusb_error_text(int libusb_error) {
    return std::string(libusb_error_name(libusb_error)) + " (" + libusb_strerror(libusb_error) + ")";
}

RRError permission_error(std::uint16_t vendor_id, std::uint16_t product_id, const std::string& device_path) {
    return make_error(MessageErrorType::SystemResourcePermissionDenied,
                      "no permission to open USB device " + hex4(vendor_id) + ":" + hex4(product_id) + " at " +
                          device_path + ": install " + kUdevRuleFile +
                          " into /etc/udev/rules.d (with this device's idVendor/idProduct), run "
                          "`udevadm control --reload && udevadm trigger`, and re-plug the device (docs/usb.md)");
}

}  // namespace rr::server::usb
