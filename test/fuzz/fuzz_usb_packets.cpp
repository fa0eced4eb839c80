// libFuzzer target for the rr+usb bulk framing and both multiplexers (base/usb): the input is a
// sequence of records {uint8 op, uint16 length, bytes}; ops feed a host multiplexer (bulk IN), a
// device function (bulk OUT, control requests), open and close streams, queue writes and move
// transfers between the two. Invariants: parsed sub-packets match their transfer size, filled
// sub-packets parse and fit the packet, unknown stream ids are InvalidEndpoint, nothing crashes.
// Seeds: test/fuzz/seeds/fuzz_usb_packets.
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <vector>

#include "base/codec/endian.hpp"
#include "base/usb/usb_device_function.hpp"
#include "base/usb/usb_host_mux.hpp"

namespace {

using namespace rr;
using namespace rr::usb;

void check(bool ok) {
    if (!ok) std::abort();
}

void check_filled(std::span<const std::byte> packet, const SubpacketScheduler::Filled& f) {
    check(f.size <= packet.size() && f.size >= kSubpacketHeaderSize);
    auto p = parse_subpacket(packet.first(f.size));
    check(p.ok());
    check(p->stream_id == f.stream_id);
    if (f.notification == Notification::Null) {
        check(p->kind == SubpacketKind::Data && p->payload.size() == f.consumed);
    } else {
        check(p->kind == SubpacketKind::Notification && p->notification == f.notification);
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    HostMux host(4);
    DeviceFunctionConfig cfg;
    cfg.max_streams = 4;
    DeviceFunction device(cfg);
    static std::vector<std::byte> payload(20000, std::byte{0x5A});
    std::array<std::byte, 64> small{};
    std::array<std::byte, 512> big{};
    std::size_t pos = 0;
    while (pos + 3 <= size) {
        const std::uint8_t op = data[pos];
        const std::size_t len = std::min<std::size_t>(data[pos + 1] | (data[pos + 2] << 8), size - pos - 3);
        const std::span<const std::byte> rec(reinterpret_cast<const std::byte*>(data + pos + 3), len);
        pos += 3 + len;
        switch (op % 8) {
            case 0: {  // raw parse
                auto p = parse_subpacket(rec);
                if (p && p->kind != SubpacketKind::Empty) check(load_le<std::uint16_t>(rec.data()) == rec.size());
                break;
            }
            case 1: {  // bulk IN at the host
                auto e = host.on_in_transfer(rec);
                if (!e) check(e.error().type == MessageErrorType::ProtocolError || e.error().type == MessageErrorType::InvalidEndpoint);
                break;
            }
            case 2: {  // bulk OUT at the device
                auto e = device.on_bulk_out(rec);
                if (!e) check(e.error().type == MessageErrorType::ProtocolError || e.error().type == MessageErrorType::InvalidEndpoint);
                break;
            }
            case 3: {  // a control request: 8 setup bytes, then the OUT data stage
                auto setup = parse_setup_packet(rec);
                if (!setup) break;
                auto o = device.on_control(*setup, rec.subspan(8), small);
                if (o) {
                    check(o->in_length <= setup->length && o->in_length <= small.size());
                    if (o->effect == ControlOutcome::Effect::StreamOpened) (void)host.stream_connected(o->stream_id);
                    if (o->effect == ControlOutcome::Effect::StreamClosed) (void)host.close_stream(o->stream_id);
                    if (o->effect == ControlOutcome::Effect::AllReset) host.reset();
                }
                break;
            }
            case 4: {  // queue writes on both sides
                const std::int32_t id = len > 0 ? std::to_integer<std::int32_t>(rec[0]) % 8 : 1;
                const std::size_t n = len > 1 ? std::to_integer<std::size_t>(rec[1]) * 70 : 100;
                (void)host.out().set_pending(id, std::span<const std::byte>(payload).first(n));
                (void)device.send(id, std::span<const std::byte>(payload).first(n));
                break;
            }
            case 5: {  // move transfers both ways
                const bool use_small = len > 0 && (std::to_integer<int>(rec[0]) & 1);
                std::span<std::byte> packet = use_small ? std::span<std::byte>(small) : std::span<std::byte>(big);
                for (int i = 0; i < 4; ++i) {
                    if (auto f = host.out().fill(packet)) {
                        check_filled(packet, *f);
                        auto e = device.on_bulk_out(packet.first(f->size));
                        if (!e) check(e.error().type == MessageErrorType::InvalidEndpoint);
                    }
                    if (auto f = device.fill_bulk_in(packet)) {
                        check_filled(packet, *f);
                        auto e = host.on_in_transfer(packet.first(f->size));
                        if (!e) check(e.error().type == MessageErrorType::InvalidEndpoint);
                    }
                }
                break;
            }
            case 6: {  // device-side close / pause
                const std::int32_t id = len > 0 ? std::to_integer<std::int32_t>(rec[0]) % 8 : 1;
                if (len > 1 && (std::to_integer<int>(rec[1]) & 1)) (void)device.close_stream(id);
                else (void)device.pause_receive(id, len > 1 && (std::to_integer<int>(rec[1]) & 2));
                break;
            }
            default: {  // host-side close
                const std::int32_t id = len > 0 ? std::to_integer<std::int32_t>(rec[0]) % 8 : 1;
                (void)host.close_stream(id);
                break;
            }
        }
    }
    return 0;
}
