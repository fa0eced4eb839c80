// The Robot Raconteur USB device protocol ("rr+usb", wire.md §10): constants, the 8-byte control
// setup packet, and the bulk sub-packet framing that multiplexes RR byte streams over one interface.
//
// Facts (CORE robotraconteur/robotraconteur, RobotRaconteurCore/src/):
//   HardwareTransport_usbcommon_private.h  – UUIDs, request codes, flags, notification codes, layouts;
//   HardwareTransport_usbcommon.cpp        – how the host uses them (claim sequence, framing checks);
//   HardwareTransport_libusb.cpp           – detection (BOS platform capability, allow-list).
// docs/usb.md describes the protocol in full; every integer is little-endian.
//
// Sub-packet (one per bulk transfer, in both directions):
//   uint16 wLength   – whole sub-packet including this 8-byte header; must equal the transfer size
//   uint16 wFlags    – 0 data, 1 command (never defined; CORE drops the device), 2 notification
//   int32  lStreamId – the RR stream the payload belongs to
//   payload          – data: wLength-8 bytes of the stream; notification: uint16 code (1 closed,
//                      2 pause request, 3 resume request)
// A transfer is at most the bulk endpoint's wMaxPacketSize (CORE sizes its buffers so), which bounds
// wLength. Zero-length transfers carry nothing and are ignored.
//
// Sans-IO, no exceptions: parse functions return Result (ProtocolError naming the fault).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "base/error/rr_error.hpp"

namespace rr::usb {

/// BOS platform capability UUID of an RR device, as its 16 bytes appear in the descriptor
/// (84670ec3-cec6-4917-b039-510e3e71788b with the first three fields little-endian, as USB writes UUIDs).
inline constexpr std::array<std::uint8_t, 16> kPlatformCapabilityUuid = {
    0xc3, 0x0e, 0x67, 0x84, 0xc6, 0xce, 0x17, 0x49, 0xb0, 0x39, 0x51, 0x0e, 0x3e, 0x71, 0x78, 0x8b};
/// CORE also defines this "CS interface detect" UUID ({3F810FD2-2BCE-4552-98F3-A8AC220AD48D}, its WinUSB
/// device interface GUID on Windows); the libusb host does not use it. Kept for reference.
inline constexpr std::array<std::uint8_t, 16> kCsInterfaceDetectUuid = {
    0x3F, 0x81, 0x0F, 0xD2, 0x2B, 0xCE, 0x45, 0x52, 0x98, 0xF3, 0xA8, 0xAC, 0x22, 0x0A, 0xD4, 0x8D};

/// Version carried by the BOS capability (bytes 16–17), the descriptor set header (wRRVersionCode)
/// and the interface descriptor (wVersion).
inline constexpr std::uint16_t kDescriptorVersion = 0x0100;
/// The stream protocol: listed in the interface descriptor's wProtocols, selected by CURRENT_PROTOCOL.
inline constexpr std::uint16_t kStreamProtocol = 0x0101;
/// bRequest of the vendor request that reads the RR descriptor set (CORE uses 0xBA whatever the BOS
/// capability's vendor-code byte says).
inline constexpr std::uint8_t kDescriptorRequest = 0xBA;
/// High byte of wIndex in the descriptor-set request (RR_USB_VENDOR_SETUP_DEFAULT_DESCRIPTOR_INDEX).
inline constexpr std::uint8_t kDescriptorSetIndex = 0x05;
/// bmRequestType: IN | vendor | interface, and OUT | vendor | interface.
inline constexpr std::uint8_t kVendorInterfaceIn = 0xC1;
inline constexpr std::uint8_t kVendorInterfaceOut = 0x41;
/// CORE's RR_USB_MAX_PACKET_SIZE: no sub-packet is larger.
inline constexpr std::size_t kMaxPacketSize = 16384;
inline constexpr std::size_t kSubpacketHeaderSize = 8;

/// bRequest of the stream control requests (vendor, interface recipient, wIndex = interface number).
/// Data stages: CONNECT_STREAM IN 4 bytes (int32 stream id, negative = refused); CLOSE_STREAM OUT
/// 4 bytes (int32 stream id); RESET_ALL_STREAM IN 4 bytes (int32 status, 0); PAUSE_ALL_STREAM and
/// RESUME_ALL_STREAM IN 4 bytes (int32 status; CORE never sends them, this shape is ours, docs/usb.md);
/// CURRENT_PROTOCOL OUT 2 bytes (uint16 kStreamProtocol).
enum class ControlRequest : std::uint8_t {
    Null = 0,
    ConnectStream = 1,
    CloseStream = 2,
    ResetAllStream = 3,
    PauseAllStream = 4,
    ResumeAllStream = 5,
    CurrentProtocol = 6,
};

/// wFlags of a sub-packet.
enum class SubpacketFlags : std::uint16_t { Data = 0, Command = 1, Notification = 2 };

/// Notification codes (payload of a notification sub-packet).
enum class Notification : std::uint16_t { Null = 0, SocketClosed = 1, PauseRequest = 2, ResumeRequest = 3 };

std::string_view control_request_name(std::uint8_t request) noexcept;
std::string_view notification_name(Notification n) noexcept;

/// The 8-byte SETUP stage of a control transfer.
struct SetupPacket {
    std::uint8_t request_type = 0;  ///< bmRequestType
    std::uint8_t request = 0;       ///< bRequest
    std::uint16_t value = 0;        ///< wValue
    std::uint16_t index = 0;        ///< wIndex
    std::uint16_t length = 0;       ///< wLength: bytes of the data stage
    bool is_in() const noexcept { return (request_type & 0x80) != 0; }
    friend bool operator==(const SetupPacket&, const SetupPacket&) = default;
};

inline constexpr std::size_t kSetupPacketSize = 8;
/// Parses the first 8 bytes. Errors: ProtocolError when fewer than 8.
Result<SetupPacket> parse_setup_packet(std::span<const std::byte> bytes);
void write_setup_packet(std::span<std::byte, kSetupPacketSize> out, const SetupPacket& setup) noexcept;

/// Setup packets of the RR requests, as the host sends them (wire.md §10).
SetupPacket descriptor_set_request(std::uint8_t interface_number, std::uint16_t length) noexcept;
SetupPacket stream_control_request(ControlRequest request, std::uint8_t interface_number) noexcept;

/// What a bulk transfer carried.
enum class SubpacketKind {
    Empty,         ///< zero-length transfer (ignored; CORE's host sends one after RESET_ALL_STREAM)
    Data,          ///< `payload` belongs to stream `stream_id`
    Notification,  ///< `notification` for stream `stream_id`
    Command,       ///< wFlags 1: no command is defined; the receiver treats it as a protocol fault
};

struct Subpacket {
    SubpacketKind kind = SubpacketKind::Empty;
    std::int32_t stream_id = 0;
    std::span<const std::byte> payload;  ///< Data: the stream bytes (may be empty); else the raw payload
    Notification notification = Notification::Null;
};

/// Parses one bulk transfer as a sub-packet. Checks, each a ProtocolError with the numbers:
///   size 1..7 (shorter than the header); size > kMaxPacketSize; wLength != size (a length field
///   larger or smaller than the transfer); wFlags not 0/1/2; negative stream id on data or
///   notification; a notification with fewer than 2 payload bytes or an unknown code.
/// The returned spans point into `transfer`.
Result<Subpacket> parse_subpacket(std::span<const std::byte> transfer);

/// Writes a data sub-packet carrying `payload` into `out`; returns its size (8 + payload.size()).
/// Precondition: out.size() >= 8 + payload.size(), 8 + payload.size() <= kMaxPacketSize, id >= 0.
std::size_t write_data_subpacket(std::span<std::byte> out, std::int32_t stream_id,
                                 std::span<const std::byte> payload) noexcept;
/// Writes the 8-byte header only (the payload already sits at out[8..]); returns 8 + payload_size.
std::size_t write_data_header(std::span<std::byte> out, std::int32_t stream_id, std::size_t payload_size) noexcept;
inline constexpr std::size_t kNotificationSize = kSubpacketHeaderSize + 2;
/// Writes a 10-byte notification sub-packet. Precondition: out.size() >= 10.
std::size_t write_notification(std::span<std::byte> out, std::int32_t stream_id, Notification n) noexcept;

}  // namespace rr::usb
