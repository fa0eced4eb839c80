// Host side of an rr+usb link (wire.md §10; docs/usb.md): the streams a host opened on one claimed
// interface, what each bulk IN transfer means for them, and (through SubpacketScheduler) what the next
// bulk OUT transfer carries.
//
// The host's link sequence (CORE HardwareTransport_usbcommon.cpp UsbDevice_Claim, and ours):
//   claim interface → RESET_ALL_STREAM (IN, 4 bytes) → zero-length bulk OUT → CURRENT_PROTOCOL
//   (OUT, 0x0101) → keep bulk IN reads pending → per RR connection CONNECT_STREAM (IN, int32 id ≥ 0)
//   → stream_connected(id). A local close sends CLOSE_STREAM (OUT, int32 id) unless the device closed
//   the stream first; the last close ends with RESET_ALL_STREAM and the interface is released.
//
// Inbound faults are classified by the error's type:
//   ProtocolError   – the transfer is malformed or a command sub-packet: the link is broken; drop it
//                     (CORE closes the device on these);
//   InvalidEndpoint – data or a notification for a stream id the host never opened: the transfer is
//                     dropped and the link goes on (CORE ignores these silently).
// Data for a stream the host closed a moment ago is expected (it was in flight) and ignored quietly.
//
// Not thread-safe; no allocation per transfer.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "base/usb/usb_inbound.hpp"
#include "base/usb/usb_scheduler.hpp"

namespace rr::usb {

/// What a bulk IN transfer from the device meant (Closed: the device closed the stream, forgotten here,
/// no CLOSE_STREAM needed; Ignored: zero-length, or late data for a stream closed a moment ago).
using HostEvent = StreamEvent;

class HostMux {
public:
    explicit HostMux(std::size_t max_streams = 16);

    /// A CONNECT_STREAM answered `id`. Errors: InvalidArgument (negative or duplicate id),
    /// OutOfSystemResource (table full).
    Result<void> stream_connected(std::int32_t id);
    /// The host closes `id`: forgotten, its later data ignored. True when the device must be told
    /// (CLOSE_STREAM); false when the stream was unknown or the device closed it first.
    bool close_stream(std::int32_t id);
    bool is_open(std::int32_t id) const noexcept { return out_.contains(id); }
    std::size_t stream_count() const noexcept { return out_.size(); }
    /// RESET_ALL_STREAM sent or the device is gone: every stream forgotten.
    void reset();

    /// Interprets one bulk IN transfer (see the header comment for the error classes).
    Result<HostEvent> on_in_transfer(std::span<const std::byte> transfer);

    /// Outbound: set_pending per stream, fill() per free OUT transfer buffer.
    SubpacketScheduler& out() noexcept { return out_; }
    const SubpacketScheduler& out() const noexcept { return out_; }

private:
    bool recently_closed(std::int32_t id) const noexcept;
    void remember_closed(std::int32_t id) noexcept;

    SubpacketScheduler out_;
    static constexpr std::size_t kClosedMemory = 32;
    std::array<std::int32_t, kClosedMemory> closed_{};
    std::size_t closed_count_ = 0, closed_next_ = 0;
};

}  // namespace rr::usb
