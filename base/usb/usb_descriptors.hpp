// Descriptors of an RR USB device (wire.md §10; docs/usb.md): how a host recognises one and what it
// reads before opening streams, and the standard descriptors a device (or the test emulator) presents.
//
//  * BOS platform capability (USB 3.2 §9.6.2.4, dev cap type 0x05): bLength 24, bDescriptorType 0x10,
//    bDevCapabilityType 0x05, bReserved, then a 20-byte body: the RR UUID (kPlatformCapabilityUuid),
//    uint16 version 0x0100, uint8 interface number, uint8 vendor request code.
//    (CORE HardwareTransport_libusb.cpp reads it from sysfs `bos_descriptors` or libusb's BOS.)
//  * RR descriptor set, read with the vendor request 0xBA (usb_protocol.hpp descriptor_set_request):
//    header {uint16 wLength 8, uint16 wDescriptorType 0, uint16 wRRVersionCode 0x0100,
//    uint16 wTotalLength}, then records {uint16 wLength, uint16 wDescriptorType, uint16
//    wDescriptorSubType, …}; type 1 subtype 0 is the interface descriptor {…, int16 wVersion 0x0100,
//    uint8 iNodeID, uint8 iNodeName, uint16 wNumProtocols, uint16 wProtocols[]} (12 + 2n bytes).
//    (CORE HardwareTransport_usbcommon_private.h structs, usbcommon.cpp ParseRRDescriptors.)
//  * iNodeID / iNodeName are string descriptor indexes (UTF-16LE, USB 2.0 §9.6.7): the NodeID text
//    and the NodeName.
//
// Parsers are strict where CORE is lax (CORE loops forever on a zero-length record and reads
// wProtocols past the record); every fault is a ProtocolError naming it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "base/error/rr_error.hpp"

namespace rr::usb {

// --- BOS ---------------------------------------------------------------------------------------

/// The RR platform capability's payload.
struct PlatformCapability {
    std::uint8_t interface_number = 0;
    std::uint8_t vendor_code = 0;
    friend bool operator==(const PlatformCapability&, const PlatformCapability&) = default;
};

inline constexpr std::uint8_t kBosDescriptorType = 0x0F;
inline constexpr std::uint8_t kDeviceCapabilityType = 0x10;
inline constexpr std::uint8_t kPlatformCapabilityType = 0x05;
inline constexpr std::size_t kBosHeaderSize = 5;
inline constexpr std::size_t kPlatformCapabilitySize = 24;

/// Finds the RR platform capabilities in a whole BOS descriptor (5-byte header + device
/// capabilities, as in sysfs `bos_descriptors` or a GET_DESCRIPTOR(BOS) answer). Other capabilities,
/// other platform UUIDs, and RR capabilities of another size or version are skipped (as CORE).
/// Errors: ProtocolError for a malformed BOS (short header, wrong type, wTotalLength beyond the bytes,
/// a capability shorter than 3 bytes or running past wTotalLength).
Result<std::vector<PlatformCapability>> find_platform_capabilities(std::span<const std::byte> bos);

/// A BOS descriptor holding one RR platform capability (29 bytes).
std::vector<std::byte> build_bos_descriptor(const PlatformCapability& cap);

// --- RR descriptor set ------------------------------------------------------------------------------

/// What the host learns from the RR descriptor set.
struct DescriptorSet {
    std::uint8_t node_id_string = 0;    ///< iNodeID
    std::uint8_t node_name_string = 0;  ///< iNodeName
    std::vector<std::uint16_t> protocols;  ///< wProtocols
    bool supports_stream_protocol() const noexcept;
    friend bool operator==(const DescriptorSet&, const DescriptorSet&) = default;
};

inline constexpr std::size_t kDescriptorSetHeaderSize = 8;
inline constexpr std::uint16_t kDescriptorSetType = 0;       ///< header wDescriptorType ("BOS" in CORE)
inline constexpr std::uint16_t kInterfaceDescriptorType = 1;  ///< record type of the interface descriptor
inline constexpr std::size_t kInterfaceDescriptorMinSize = 12;

/// Checks the 8-byte header (the host's first read) and returns wTotalLength.
/// Errors: ProtocolError: fewer than 8 bytes, wDescriptorType != 0, wTotalLength < 8.
Result<std::uint16_t> parse_descriptor_set_length(std::span<const std::byte> header);

/// Parses the whole set (the first wTotalLength bytes of `bytes`).
/// Errors: ProtocolError: header faults as above, wRRVersionCode != 0x0100, wTotalLength beyond the
/// bytes, a record shorter than 6 bytes or past the end, an interface descriptor shorter than 12
/// bytes, wVersion != 0x0100, wNumProtocols beyond the record, two interface descriptors, none.
Result<DescriptorSet> parse_descriptor_set(std::span<const std::byte> bytes);

/// The set with one interface descriptor; protocols empty means {kStreamProtocol}.
std::vector<std::byte> build_descriptor_set(const DescriptorSet& set);

// --- String descriptors -----------------------------------------------------------------------------

inline constexpr std::uint8_t kStringDescriptorType = 0x03;
inline constexpr std::uint16_t kLangIdEnglishUs = 0x0409;
/// At most 126 UTF-16 code units fit a string descriptor (bLength is one byte).
inline constexpr std::size_t kMaxStringUnits = 126;

/// String descriptor 0: the first LANGID. Errors: ProtocolError (bLength/type/size faults, no LANGID).
Result<std::uint16_t> parse_language_ids(std::span<const std::byte> bytes);
/// A string descriptor as UTF-8; text ends at the first NUL code unit (as CORE's conversion).
/// Errors: ProtocolError: bLength != bytes, type != 3, odd length, unpaired surrogate.
Result<std::string> parse_string_descriptor(std::span<const std::byte> bytes);
/// Encodes UTF-8 text. Errors: InvalidArgument for invalid UTF-8 or more than 126 UTF-16 units.
Result<std::vector<std::byte>> build_string_descriptor(std::string_view utf8);
std::vector<std::byte> build_language_ids(std::uint16_t langid = kLangIdEnglishUs);

// --- Standard device descriptors (device side) ------------------------------------------------------

/// The layout of an RR USB device with one vendor interface of two bulk endpoints.
struct DeviceLayout {
    std::uint16_t vendor_id = 0x1209;   ///< pid.codes
    std::uint16_t product_id = 0x0001;  ///< pid.codes test PID
    std::uint16_t bcd_device = 0x0100;
    std::uint8_t device_class = 0xFF;   ///< 0x00 or 0xFF (CORE accepts only these)
    std::uint8_t manufacturer_string = 1, product_string = 2, serial_string = 3;
    std::uint8_t interface_number = 0;
    std::uint8_t interface_class = 0xFF;  ///< vendor; CORE requires 0xFF
    std::uint8_t in_endpoint = 0x81, out_endpoint = 0x01;
    std::uint16_t max_packet_size = 512;  ///< wMaxPacketSize of both bulk endpoints (sub-packet size)
    std::uint8_t configuration_value = 1;
};

/// 18-byte device descriptor, bcdUSB 0x0210 (a BOS needs ≥ 2.01), bMaxPacketSize0 64, one configuration.
std::vector<std::byte> build_device_descriptor(const DeviceLayout& layout);
/// Configuration descriptor with the interface and its two bulk endpoints (9 + 9 + 7 + 7 bytes).
std::vector<std::byte> build_configuration_descriptor(const DeviceLayout& layout);

}  // namespace rr::usb
