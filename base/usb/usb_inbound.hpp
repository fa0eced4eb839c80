// Inbound half of an rr+usb link, shared by the host (usb_host_mux.hpp) and the device
// (usb_device_function.hpp): what one bulk transfer from the peer (one sub-packet, wire.md §10) means
// for the streams open on this side. Not thread-safe; no allocation.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "base/error/rr_error.hpp"
#include "base/usb/usb_scheduler.hpp"

namespace rr::usb {

struct StreamEvent {
    enum class Kind {
        Ignored,  ///< zero-length transfer, or data/notification for a stream in `tolerated` (closed a moment ago)
        Data,     ///< `payload` (a view into the transfer) for `stream_id`
        Closed,   ///< the peer sent "socket closed" for `stream_id`; it is removed from `out`
        Paused,   ///< the peer asked us to stop sending on `stream_id`
        Resumed,  ///< … and to go on
    };
    Kind kind = Kind::Ignored;
    std::int32_t stream_id = 0;
    std::span<const std::byte> payload;
};

/// Applies one inbound sub-packet to `out` (pause, resume, close) and says what it was. `peer` names
/// the sender in error messages ("USB host", "USB device"); `tolerated` lists stream ids whose late
/// data is expected and ignored.
/// Errors: ProtocolError (malformed transfer, or a command sub-packet, which the protocol does not
/// define: the link is broken); InvalidEndpoint (data or a notification for a stream that is not open
/// and not tolerated: drop the transfer, the link goes on).
Result<StreamEvent> read_inbound_subpacket(SubpacketScheduler& out, std::span<const std::byte> transfer,
                                           std::string_view peer, std::span<const std::int32_t> tolerated = {});

}  // namespace rr::usb
