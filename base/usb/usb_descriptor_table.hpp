// The standard descriptors of an RR USB device, built once, and the answers to the standard
// GET_DESCRIPTOR requests a host sends it (device, configuration, BOS, strings – USB 2.0 §9.4.3).
// For firmware without a descriptor generator of its own, and for the test emulator (which also
// writes `descriptors` / `bos_descriptors` into the emulated sysfs from here).
//
// Strings: 1 manufacturer, 2 product, 3 serial (DeviceLayout indexes), and the NodeID text and
// NodeName at DeviceFunctionConfig::node_id_string / node_name_string.
#pragma once

#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "base/names/node_id.hpp"
#include "base/usb/usb_descriptors.hpp"
#include "base/usb/usb_device_function.hpp"
#include "base/usb/usb_protocol.hpp"

namespace rr::usb {

struct DeviceStrings {
    std::string manufacturer = "Robot Raconteur";
    std::string product = "RR USB device";
    std::string serial = "0001";
    NodeID node_id;
    std::string node_name;
};

class DescriptorTable {
public:
    /// Errors: InvalidArgument (a string that does not fit a string descriptor, index clashes,
    /// an all-zero NodeID).
    /// `with_bos`: advertise the RR platform capability (a device without it is found only through
    /// the host's (VID, PID, interface) allow-list).
    static Result<DescriptorTable> build(const DeviceLayout& layout, const DeviceStrings& strings,
                                         const DeviceFunctionConfig& function, bool with_bos = true,
                                         std::uint8_t vendor_code = kDescriptorRequest);

    std::span<const std::byte> device() const noexcept { return device_; }
    std::span<const std::byte> configuration() const noexcept { return configuration_; }
    /// Empty when built without the BOS capability.
    std::span<const std::byte> bos() const noexcept { return bos_; }
    /// Device descriptor followed by the configuration descriptor (Linux sysfs `descriptors`).
    std::vector<std::byte> sysfs_descriptors() const;

    /// Answers a standard GET_DESCRIPTOR (bmRequestType 0x80, bRequest 6); the caller returns at most
    /// setup.length bytes of it. Errors (answer with STALL): NotImplementedError for other requests,
    /// ResourceNotFound for a descriptor the device does not have.
    Result<std::span<const std::byte>> get_descriptor(const SetupPacket& setup) const;

private:
    std::vector<std::byte> device_, configuration_, bos_, langids_;
    std::map<std::uint8_t, std::vector<std::byte>> strings_;
};

}  // namespace rr::usb
