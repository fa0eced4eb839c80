// rr+usb framing: setup packets of the RR requests and the bulk sub-packet parser's bounds checks.
#include <catch2/catch.hpp>

#include <vector>

#include "base/usb/usb_protocol.hpp"

using namespace rr;
using namespace rr::usb;

namespace {

std::vector<std::byte> bytes(std::initializer_list<int> v) {
    std::vector<std::byte> out;
    for (int b : v) out.push_back(static_cast<std::byte>(b));
    return out;
}

std::vector<std::byte> subpacket(std::uint16_t len, std::uint16_t flags, std::int32_t id, std::vector<std::byte> payload) {
    std::vector<std::byte> out = bytes({len & 0xFF, len >> 8, flags & 0xFF, flags >> 8, id & 0xFF, (id >> 8) & 0xFF,
                                        (id >> 16) & 0xFF, int((static_cast<std::uint32_t>(id) >> 24) & 0xFF)});
    out.insert(out.end(), payload.begin(), payload.end());
    return out;
}

bool mentions(const RRError& e, std::string_view what) { return e.message.find(what) != std::string::npos; }

}  // namespace

TEST_CASE("usb: setup packets of the RR requests have CORE's request types, codes and indexes") {
    const auto d = descriptor_set_request(2, 8);
    CHECK(d.request_type == 0xC1);
    CHECK(d.request == 0xBA);
    CHECK(d.value == 0);
    CHECK(d.index == 0x0502);
    CHECK(d.length == 8);

    CHECK(stream_control_request(ControlRequest::ConnectStream, 0) == SetupPacket{0xC1, 1, 0, 0, 4});
    CHECK(stream_control_request(ControlRequest::CloseStream, 3) == SetupPacket{0x41, 2, 0, 3, 4});
    CHECK(stream_control_request(ControlRequest::ResetAllStream, 0) == SetupPacket{0xC1, 3, 0, 0, 4});
    CHECK(stream_control_request(ControlRequest::PauseAllStream, 0) == SetupPacket{0xC1, 4, 0, 0, 4});
    CHECK(stream_control_request(ControlRequest::ResumeAllStream, 0) == SetupPacket{0xC1, 5, 0, 0, 4});
    CHECK(stream_control_request(ControlRequest::CurrentProtocol, 0) == SetupPacket{0x41, 6, 0, 0, 2});

    std::array<std::byte, 8> raw{};
    write_setup_packet(raw, d);
    CHECK(std::vector<std::byte>(raw.begin(), raw.end()) == bytes({0xC1, 0xBA, 0, 0, 0x02, 0x05, 8, 0}));
    auto back = parse_setup_packet(raw);
    REQUIRE(back);
    CHECK(*back == d);
    CHECK_FALSE(parse_setup_packet(std::span<const std::byte>(raw).first(7)));
}

TEST_CASE("usb: a data sub-packet round-trips and its payload is the transfer after the header") {
    std::array<std::byte, 64> buf{};
    const auto payload = bytes({'R', 'R', 'A', 'C'});
    const auto n = write_data_subpacket(buf, 7, payload);
    CHECK(n == 12);
    CHECK(std::vector<std::byte>(buf.begin(), buf.begin() + 8) == bytes({12, 0, 0, 0, 7, 0, 0, 0}));
    auto p = parse_subpacket(std::span<const std::byte>(buf).first(n));
    REQUIRE(p);
    CHECK(p->kind == SubpacketKind::Data);
    CHECK(p->stream_id == 7);
    CHECK(std::vector<std::byte>(p->payload.begin(), p->payload.end()) == payload);

    // A header-only data sub-packet is valid (no bytes) and so is a zero-length transfer (ignored).
    auto empty_data = parse_subpacket(subpacket(8, 0, 1, {}));
    REQUIRE(empty_data);
    CHECK(empty_data->kind == SubpacketKind::Data);
    CHECK(empty_data->payload.empty());
    auto zlp = parse_subpacket({});
    REQUIRE(zlp);
    CHECK(zlp->kind == SubpacketKind::Empty);
}

TEST_CASE("usb: notifications carry a uint16 code") {
    std::array<std::byte, 16> buf{};
    for (auto n : {Notification::SocketClosed, Notification::PauseRequest, Notification::ResumeRequest}) {
        const auto size = write_notification(buf, 3, n);
        CHECK(size == 10);
        auto p = parse_subpacket(std::span<const std::byte>(buf).first(size));
        REQUIRE(p);
        CHECK(p->kind == SubpacketKind::Notification);
        CHECK(p->notification == n);
        CHECK(p->stream_id == 3);
    }
    CHECK(std::vector<std::byte>(buf.begin(), buf.begin() + 10) == bytes({10, 0, 2, 0, 3, 0, 0, 0, 3, 0}));
}

TEST_CASE("usb: malformed sub-packets are clear protocol errors") {
    for (std::size_t n = 1; n < 8; ++n) {
        std::vector<std::byte> t(n, std::byte{0});
        auto p = parse_subpacket(t);
        REQUIRE_FALSE(p);
        CHECK(p.error().type == MessageErrorType::ProtocolError);
        CHECK(mentions(p.error(), "shorter than the 8-byte header"));
    }
    auto longer = parse_subpacket(subpacket(40, 0, 1, bytes({1, 2, 3, 4})));
    REQUIRE_FALSE(longer);
    CHECK(mentions(longer.error(), "length field 40 is larger than the 12-byte transfer"));
    auto shorter = parse_subpacket(subpacket(9, 0, 1, bytes({1, 2, 3, 4})));
    REQUIRE_FALSE(shorter);
    CHECK(mentions(shorter.error(), "does not match"));
    auto flags = parse_subpacket(subpacket(8, 0x80, 1, {}));
    REQUIRE_FALSE(flags);
    CHECK(mentions(flags.error(), "unknown flags 0x0080"));
    auto negative = parse_subpacket(subpacket(9, 0, -5, bytes({1})));
    REQUIRE_FALSE(negative);
    CHECK(mentions(negative.error(), "negative stream id -5"));
    auto short_note = parse_subpacket(subpacket(9, 2, 1, bytes({1})));
    REQUIRE_FALSE(short_note);
    CHECK(mentions(short_note.error(), "notification with 1 payload bytes"));
    auto bad_code = parse_subpacket(subpacket(10, 2, 1, bytes({9, 0})));
    REQUIRE_FALSE(bad_code);
    CHECK(mentions(bad_code.error(), "unknown notification code 9"));
    std::vector<std::byte> huge(kMaxPacketSize + 1, std::byte{0});
    auto too_big = parse_subpacket(huge);
    REQUIRE_FALSE(too_big);
    CHECK(mentions(too_big.error(), "exceeds"));
    // A command sub-packet parses (the multiplexers reject it).
    auto command = parse_subpacket(subpacket(8, 1, 0, {}));
    REQUIRE(command);
    CHECK(command->kind == SubpacketKind::Command);
}

TEST_CASE("usb: request and notification names") {
    CHECK(control_request_name(1) == "CONNECT_STREAM");
    CHECK(control_request_name(6) == "CURRENT_PROTOCOL");
    CHECK(control_request_name(0xBA) == "GET_RR_DESCRIPTOR_SET");
    CHECK(control_request_name(99) == "unknown");
    CHECK(notification_name(Notification::PauseRequest) == "pause request");
}
