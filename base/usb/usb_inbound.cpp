#include "base/usb/usb_inbound.hpp"

#include <algorithm>
#include <string>

#include "base/usb/usb_protocol.hpp"

namespace rr::usb {

Result<StreamEvent> read_inbound_subpacket(SubpacketScheduler& out, std::span<const std::byte> transfer,
                                           std::string_view peer, std::span<const std::int32_t> tolerated) {
    auto p = parse_subpacket(transfer);
    if (!p) return p.take_error();
    StreamEvent ev;
    ev.stream_id = p->stream_id;
    switch (p->kind) {
        case SubpacketKind::Empty:
            return ev;
        case SubpacketKind::Command:
            return fail(MessageErrorType::ProtocolError,
                        std::string(peer) + " sent a command sub-packet (flags 1), which the protocol does not define");
        case SubpacketKind::Data:
        case SubpacketKind::Notification:
            break;
    }
    if (!out.contains(p->stream_id)) {
        if (std::find(tolerated.begin(), tolerated.end(), p->stream_id) != tolerated.end()) return ev;
        return fail(MessageErrorType::InvalidEndpoint,
                    std::string(peer) + " sent " + (p->kind == SubpacketKind::Data ? "data" : "a notification") +
                        " for stream " + std::to_string(p->stream_id) + ", which is not open");
    }
    if (p->kind == SubpacketKind::Data) {
        ev.kind = StreamEvent::Kind::Data;
        ev.payload = p->payload;
        return ev;
    }
    switch (p->notification) {
        case Notification::SocketClosed:
            out.remove(p->stream_id);
            ev.kind = StreamEvent::Kind::Closed;
            return ev;
        case Notification::PauseRequest:
            out.set_paused(p->stream_id, true);
            ev.kind = StreamEvent::Kind::Paused;
            return ev;
        case Notification::ResumeRequest:
            out.set_paused(p->stream_id, false);
            ev.kind = StreamEvent::Kind::Resumed;
            return ev;
        case Notification::Null:
            break;
    }
    return ev;  // parse_subpacket admits no other code
}

}  // namespace rr::usb
