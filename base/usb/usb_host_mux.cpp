#include "base/usb/usb_host_mux.hpp"

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
    auto ev = read_inbound_subpacket(out_, transfer, "USB device", std::span(closed_.data(), closed_count_));
    if (ev && ev->kind == HostEvent::Kind::Closed) remember_closed(ev->stream_id);
    return ev;
}

}  // namespace rr::usb
