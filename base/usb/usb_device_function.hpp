// Device side of an rr+usb link, for firmware and device emulators (docs/usb.md "Writing a device"):
// the vendor control requests of the RR interface in, bulk OUT sub-packets in, bulk IN sub-packets
// out, and the streams they multiplex. The USB stack around it (endpoint 0 state machine, standard
// requests, endpoint buffers) stays the firmware's: usb_descriptor_table.hpp answers the standard
// GET_DESCRIPTOR requests an RR device needs.
//
// Use:
//   * every SETUP whose accepts() is true → on_control(setup, OUT data stage, IN buffer); an error
//     means STALL; the outcome says how many IN bytes to return and what changed (a stream opened, …);
//   * every bulk OUT transfer → on_bulk_out(); Data events go to the stream's RR server connection;
//   * whenever the IN endpoint is free → fill_bulk_in(buffer of wMaxPacketSize) and send what it
//     wrote (nothing when it returns nullopt);
//   * the stream's RR server connection writes with send() (the bytes stay the caller's until
//     fill_bulk_in reports them drained), closes with close_stream(), and asks the host to hold off
//     with pause_receive() when it cannot take more.
//
// Stream ids are allocated here (1, 2, … skipping ids in use); at most `max_streams` at once
// (CONNECT_STREAM then answers -1, which the host reports as a refused connection).
// Not thread-safe; no allocation per transfer.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "base/usb/usb_descriptors.hpp"
#include "base/usb/usb_inbound.hpp"
#include "base/usb/usb_scheduler.hpp"

namespace rr::usb {

struct DeviceFunctionConfig {
    std::uint8_t interface_number = 0;
    std::uint8_t node_id_string = 4;    ///< string descriptor index holding the NodeID text
    std::uint8_t node_name_string = 5;  ///< string descriptor index holding the NodeName
    std::size_t max_streams = 8;
    /// Refuse CONNECT_STREAM until CURRENT_PROTOCOL selected 0x0101 (CORE's host always sends it).
    bool require_protocol = false;
};

struct ControlOutcome {
    enum class Effect {
        None,              ///< descriptor read, or a refused CONNECT_STREAM (id -1)
        StreamOpened,      ///< `stream_id` is new: start an RR server connection on it
        StreamClosed,      ///< the host closed `stream_id`: end its connection (no notification back)
        AllReset,          ///< RESET_ALL_STREAM: every stream is gone
        PausedAll,         ///< PAUSE_ALL_STREAM: no data goes to the host until ResumedAll
        ResumedAll,
        ProtocolSelected,  ///< CURRENT_PROTOCOL 0x0101
    };
    std::size_t in_length = 0;  ///< bytes written to the IN buffer (the data stage to return)
    Effect effect = Effect::None;
    std::int32_t stream_id = -1;
};

/// What a bulk OUT transfer from the host meant (Closed: the host closed the stream; Ignored: a
/// zero-length transfer, which CORE's host sends after RESET_ALL_STREAM).
using DeviceEvent = StreamEvent;

class DeviceFunction {
public:
    explicit DeviceFunction(DeviceFunctionConfig config = {});

    const DeviceFunctionConfig& config() const noexcept { return config_; }
    /// True for a vendor request with interface recipient addressed to this interface (low byte of
    /// wIndex), i.e. one on_control() handles.
    bool accepts(const SetupPacket& setup) const noexcept;
    /// Handles an RR control request. `out_data` is the OUT data stage (empty for IN requests);
    /// `in_buffer` receives the IN data stage (at most setup.length bytes are written).
    /// Errors (answer with STALL): InvalidArgument – wrong direction, short data stage, unknown
    /// stream id in CLOSE_STREAM, unsupported protocol; NotImplementedError – unknown request.
    Result<ControlOutcome> on_control(const SetupPacket& setup, std::span<const std::byte> out_data,
                                      std::span<std::byte> in_buffer);

    /// Interprets one bulk OUT transfer. Errors: ProtocolError (malformed, command sub-packet: the
    /// host is broken, reset the function), InvalidEndpoint (a stream id that is not open: drop it).
    Result<DeviceEvent> on_bulk_out(std::span<const std::byte> transfer);

    /// The next bulk IN transfer into `packet` (sized wMaxPacketSize). See SubpacketScheduler::fill.
    std::optional<SubpacketScheduler::Filled> fill_bulk_in(std::span<std::byte> packet) { return out_.fill(packet); }
    bool has_bulk_in() const noexcept { return out_.has_work(); }

    /// Bytes to send on `id` (kept valid by the caller until drained). Errors as set_pending.
    Result<void> send(std::int32_t id, std::span<const std::byte> bytes) { return out_.set_pending(id, bytes); }
    std::size_t pending(std::int32_t id) const noexcept { return out_.pending(id); }
    /// Forgets the pending write on `id` (its owner aborted it); returns the bytes dropped.
    std::size_t drop_pending(std::int32_t id) noexcept { return out_.drop_pending(id); }
    /// The device ends `id`: "socket closed" goes to the host after the pending bytes. False if unknown.
    bool close_stream(std::int32_t id) noexcept { return out_.close_after_drain(id); }
    /// Ask the host to pause (or resume) sending on `id`. Errors: InvalidArgument (not open),
    /// OutOfSystemResource (notification queue full).
    Result<void> pause_receive(std::int32_t id, bool paused);

    bool is_open(std::int32_t id) const noexcept { return out_.contains(id); }
    std::size_t stream_count() const noexcept { return out_.size(); }
    bool protocol_selected() const noexcept { return protocol_selected_; }
    bool host_paused_all() const noexcept { return out_.all_paused(); }
    /// Forget every stream (a bus reset or unplug).
    void reset() noexcept;

    /// The RR descriptor set this function serves (built from the config).
    std::span<const std::byte> descriptor_set() const noexcept { return descriptor_set_; }

private:
    DeviceFunctionConfig config_;
    SubpacketScheduler out_;
    std::vector<std::byte> descriptor_set_;
    std::int32_t next_id_ = 1;
    bool protocol_selected_ = false;
};

}  // namespace rr::usb
