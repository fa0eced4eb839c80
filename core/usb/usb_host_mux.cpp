#include "core/usb/usb_host_mux.hpp"

#include <algorithm>

namespace rr::usb {

HostMux::HostMux(std::size_t max_streams) : out_(max_streams) {}

Result<void> HostMux::stream_connected(std::int32_t id) {
    auto r = out_.add(id);
    if (!r) return r;
    // A reused id is live again: forget that it was closed.
    for (std::size_t i = 0; i < closed_count_; ++i)
        if (closed_[i] == id) closed_[i] = -1;
    return {};
}

bool HostMux::close_stream(std::int32_t id) {
    if (!out_.remove(id)) return false;
    remember_closed(id);
    return true;
}

void HostMux::reset() {
    out_.clear();
    closed_count_ = closed_next_ = 0;
}

bool HostMux::recently_closed(std::int32_t id) const noexcept {
    return std::find(closed_.begin(), closed_.begin() + static_cast<std::ptrdiff_t>(closed_count_), id) !=
           closed_.begin() + static_cast<std::ptrdiff_t>(closed_count_);
}

void HostMux::remember_closed(std::int32_t id) noexcept {
    closed_[closed_next_] = id;
    closed_next_ = (closed_next_ + 1) % kClosedMemory;
    closed_count_ = std::min(closed_count_ + 1, kClosedMemory);
}

Result<HostEvent> HostMux::on_in_transfer(std::span<const std::byte> transfer) {
    auto p = parse_subpacket(transfer);
    if (!p) return p.take_error();
    HostEvent ev;
    ev.stream_id = p->stream_id;
    switch (p->kind) {
        case SubpacketKind::Empty:
            return ev;
        case SubpacketKind::Command:
            return fail(MessageErrorType::ProtocolError,
                        "USB device sent a command sub-packet (flags 1), which the protocol does not define");
        case SubpacketKind::Data:
        case SubpacketKind::Notification:
            break;
    }
    if (!out_.contains(p->stream_id)) {
        if (recently_closed(p->stream_id)) return ev;
        return fail(MessageErrorType::InvalidEndpoint,
                    "USB device sent " + std::string(p->kind == SubpacketKind::Data ? "data" : "a notification") +
                        " for stream " + std::to_string(p->stream_id) + ", which the host did not open");
    }
    if (p->kind == SubpacketKind::Data) {
        ev.kind = HostEvent::Kind::Data;
        ev.payload = p->payload;
        return ev;
    }
    switch (p->notification) {
        case Notification::SocketClosed:
            out_.remove(p->stream_id);
            remember_closed(p->stream_id);
            ev.kind = HostEvent::Kind::StreamClosed;
            return ev;
        case Notification::PauseRequest:
            out_.set_paused(p->stream_id, true);
            ev.kind = HostEvent::Kind::Paused;
            return ev;
        case Notification::ResumeRequest:
            out_.set_paused(p->stream_id, false);
            ev.kind = HostEvent::Kind::Resumed;
            return ev;
        case Notification::Null:
            break;
    }
    return ev;  // parse_subpacket admits no other code
}

}  // namespace rr::usb
