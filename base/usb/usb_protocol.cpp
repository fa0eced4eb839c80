#include "base/usb/usb_protocol.hpp"

#include <algorithm>

#include "base/codec/endian.hpp"

namespace rr::usb {

std::string_view control_request_name(std::uint8_t request) noexcept {
    switch (static_cast<ControlRequest>(request)) {
        case ControlRequest::Null: return "NULL";
        case ControlRequest::ConnectStream: return "CONNECT_STREAM";
        case ControlRequest::CloseStream: return "CLOSE_STREAM";
        case ControlRequest::ResetAllStream: return "RESET_ALL_STREAM";
        case ControlRequest::PauseAllStream: return "PAUSE_ALL_STREAM";
        case ControlRequest::ResumeAllStream: return "RESUME_ALL_STREAM";
        case ControlRequest::CurrentProtocol: return "CURRENT_PROTOCOL";
    }
    return request == kDescriptorRequest ? "GET_RR_DESCRIPTOR_SET" : "unknown";
}

std::string_view notification_name(Notification n) noexcept {
    switch (n) {
        case Notification::Null: return "null";
        case Notification::SocketClosed: return "socket closed";
        case Notification::PauseRequest: return "pause request";
        case Notification::ResumeRequest: return "resume request";
    }
    return "unknown";
}

Result<SetupPacket> parse_setup_packet(std::span<const std::byte> bytes) {
    if (bytes.size() < kSetupPacketSize)
        return fail(MessageErrorType::ProtocolError,
                    "USB setup packet of " + std::to_string(bytes.size()) + " bytes (8 needed)");
    SetupPacket s;
    s.request_type = static_cast<std::uint8_t>(bytes[0]);
    s.request = static_cast<std::uint8_t>(bytes[1]);
    s.value = load_le<std::uint16_t>(bytes.data() + 2);
    s.index = load_le<std::uint16_t>(bytes.data() + 4);
    s.length = load_le<std::uint16_t>(bytes.data() + 6);
    return s;
}

void write_setup_packet(std::span<std::byte, kSetupPacketSize> out, const SetupPacket& s) noexcept {
    out[0] = static_cast<std::byte>(s.request_type);
    out[1] = static_cast<std::byte>(s.request);
    store_le(out.data() + 2, s.value);
    store_le(out.data() + 4, s.index);
    store_le(out.data() + 6, s.length);
}

SetupPacket descriptor_set_request(std::uint8_t interface_number, std::uint16_t length) noexcept {
    return SetupPacket{kVendorInterfaceIn, kDescriptorRequest, 0,
                       static_cast<std::uint16_t>((kDescriptorSetIndex << 8) | interface_number), length};
}

SetupPacket stream_control_request(ControlRequest request, std::uint8_t interface_number) noexcept {
    SetupPacket s;
    s.request = static_cast<std::uint8_t>(request);
    s.index = interface_number;
    switch (request) {
        case ControlRequest::CloseStream:
            s.request_type = kVendorInterfaceOut;
            s.length = 4;
            break;
        case ControlRequest::CurrentProtocol:
            s.request_type = kVendorInterfaceOut;
            s.length = 2;
            break;
        case ControlRequest::Null:
            s.request_type = kVendorInterfaceOut;
            break;
        default:  // CONNECT_STREAM, RESET_ALL, PAUSE_ALL, RESUME_ALL: IN, a 4-byte int32
            s.request_type = kVendorInterfaceIn;
            s.length = 4;
            break;
    }
    return s;
}

namespace {
Unexpected bad(std::string what) { return fail(MessageErrorType::ProtocolError, "USB sub-packet: " + std::move(what)); }
}  // namespace

Result<Subpacket> parse_subpacket(std::span<const std::byte> transfer) {
    Subpacket p;
    if (transfer.empty()) return p;
    if (transfer.size() < kSubpacketHeaderSize)
        return bad("transfer of " + std::to_string(transfer.size()) + " bytes is shorter than the 8-byte header");
    if (transfer.size() > kMaxPacketSize)
        return bad("transfer of " + std::to_string(transfer.size()) + " bytes exceeds the " +
                   std::to_string(kMaxPacketSize) + "-byte maximum");
    const auto length = load_le<std::uint16_t>(transfer.data());
    const auto flags = load_le<std::uint16_t>(transfer.data() + 2);
    p.stream_id = load_le<std::int32_t>(transfer.data() + 4);
    if (length > transfer.size())
        return bad("length field " + std::to_string(length) + " is larger than the " +
                   std::to_string(transfer.size()) + "-byte transfer");
    if (length != transfer.size())
        return bad("length field " + std::to_string(length) + " does not match the " +
                   std::to_string(transfer.size()) + "-byte transfer");
    p.payload = transfer.subspan(kSubpacketHeaderSize);
    switch (static_cast<SubpacketFlags>(flags)) {
        case SubpacketFlags::Data:
            if (p.stream_id < 0) return bad("data for negative stream id " + std::to_string(p.stream_id));
            p.kind = SubpacketKind::Data;
            return p;
        case SubpacketFlags::Command:
            p.kind = SubpacketKind::Command;
            return p;
        case SubpacketFlags::Notification: {
            if (p.stream_id < 0) return bad("notification for negative stream id " + std::to_string(p.stream_id));
            if (p.payload.size() < 2)
                return bad("notification with " + std::to_string(p.payload.size()) + " payload bytes (2 needed)");
            const auto code = load_le<std::uint16_t>(p.payload.data());
            if (code < 1 || code > 3) return bad("unknown notification code " + std::to_string(code));
            p.kind = SubpacketKind::Notification;
            p.notification = static_cast<Notification>(code);
            return p;
        }
    }
    return bad("unknown flags 0x" + [&] {
        static constexpr char hex[] = "0123456789abcdef";
        std::string s;
        for (int shift = 12; shift >= 0; shift -= 4) s.push_back(hex[(flags >> shift) & 0xF]);
        return s;
    }());
}

std::size_t write_data_header(std::span<std::byte> out, std::int32_t stream_id, std::size_t payload_size) noexcept {
    const auto total = static_cast<std::uint16_t>(kSubpacketHeaderSize + payload_size);
    store_le(out.data(), total);
    store_le(out.data() + 2, static_cast<std::uint16_t>(SubpacketFlags::Data));
    store_le(out.data() + 4, stream_id);
    return total;
}

std::size_t write_data_subpacket(std::span<std::byte> out, std::int32_t stream_id,
                                 std::span<const std::byte> payload) noexcept {
    std::copy(payload.begin(), payload.end(), out.begin() + kSubpacketHeaderSize);
    return write_data_header(out, stream_id, payload.size());
}

std::size_t write_notification(std::span<std::byte> out, std::int32_t stream_id, Notification n) noexcept {
    store_le(out.data(), static_cast<std::uint16_t>(kNotificationSize));
    store_le(out.data() + 2, static_cast<std::uint16_t>(SubpacketFlags::Notification));
    store_le(out.data() + 4, stream_id);
    store_le(out.data() + 8, static_cast<std::uint16_t>(n));
    return kNotificationSize;
}

}  // namespace rr::usb
