#include "base/usb/usb_device_function.hpp"

#include <algorithm>
#include <limits>

#include "base/codec/endian.hpp"

namespace rr::usb {

namespace {

Unexpected stall(std::string what) { return fail(MessageErrorType::InvalidArgument, std::move(what)); }

std::size_t put_i32(std::span<std::byte> in, std::uint16_t length, std::int32_t v) {
    if (length < 4 || in.size() < 4) return 0;
    store_le(in.data(), v);
    return 4;
}

}  // namespace

DeviceFunction::DeviceFunction(DeviceFunctionConfig config)
    : config_(config), out_(config.max_streams == 0 ? 1 : config.max_streams) {
    DescriptorSet set;
    set.node_id_string = config_.node_id_string;
    set.node_name_string = config_.node_name_string;
    set.protocols = {kStreamProtocol};
    descriptor_set_ = build_descriptor_set(set);
}

bool DeviceFunction::accepts(const SetupPacket& setup) const noexcept {
    return (setup.request_type & 0x7F) == (kVendorInterfaceOut & 0x7F) &&
           (setup.index & 0xFF) == config_.interface_number;
}

void DeviceFunction::reset() noexcept {
    out_.clear();
    protocol_selected_ = false;
}

Result<ControlOutcome> DeviceFunction::on_control(const SetupPacket& setup, std::span<const std::byte> out_data,
                                                  std::span<std::byte> in_buffer) {
    if (!accepts(setup)) return stall("USB control request is not addressed to the RR interface");
    const auto name = std::string(control_request_name(setup.request));
    auto want_in = [&]() -> Result<void> {
        if (!setup.is_in()) return stall(name + " must be an IN request");
        return {};
    };
    auto want_out = [&](std::size_t n) -> Result<void> {
        if (setup.is_in()) return stall(name + " must be an OUT request");
        if (out_data.size() < n || setup.length < n)
            return stall(name + " needs " + std::to_string(n) + " data bytes, got " + std::to_string(out_data.size()));
        return {};
    };
    ControlOutcome o;
    if (setup.request == kDescriptorRequest) {
        if (auto r = want_in(); !r) return r.take_error();
        if ((setup.index >> 8) != kDescriptorSetIndex)
            return stall("RR descriptor index " + std::to_string(setup.index >> 8) + " (5 expected)");
        const std::size_t n = std::min({descriptor_set_.size(), std::size_t{setup.length}, in_buffer.size()});
        std::copy_n(descriptor_set_.begin(), n, in_buffer.begin());
        o.in_length = n;
        return o;
    }
    switch (static_cast<ControlRequest>(setup.request)) {
        case ControlRequest::ConnectStream: {
            if (auto r = want_in(); !r) return r.take_error();
            if (setup.length < 4) return stall("CONNECT_STREAM needs a 4-byte data stage");
            if ((config_.require_protocol && !protocol_selected_) || out_.size() >= out_.max_streams()) {
                o.in_length = put_i32(in_buffer, setup.length, -1);
                return o;
            }
            std::int32_t id = next_id_;
            while (out_.contains(id)) id = id == std::numeric_limits<std::int32_t>::max() ? 1 : id + 1;
            next_id_ = id == std::numeric_limits<std::int32_t>::max() ? 1 : id + 1;
            if (auto r = out_.add(id); !r) return r.take_error();
            o.in_length = put_i32(in_buffer, setup.length, id);
            o.effect = ControlOutcome::Effect::StreamOpened;
            o.stream_id = id;
            return o;
        }
        case ControlRequest::CloseStream: {
            if (auto r = want_out(4); !r) return r.take_error();
            const auto id = load_le<std::int32_t>(out_data.data());
            if (!out_.remove(id)) return stall("CLOSE_STREAM for stream " + std::to_string(id) + ", which is not open");
            o.effect = ControlOutcome::Effect::StreamClosed;
            o.stream_id = id;
            return o;
        }
        case ControlRequest::ResetAllStream:
            if (auto r = want_in(); !r) return r.take_error();
            out_.clear();
            o.in_length = put_i32(in_buffer, setup.length, 0);
            o.effect = ControlOutcome::Effect::AllReset;
            return o;
        case ControlRequest::PauseAllStream:
        case ControlRequest::ResumeAllStream: {
            if (auto r = want_in(); !r) return r.take_error();
            const bool pause = static_cast<ControlRequest>(setup.request) == ControlRequest::PauseAllStream;
            out_.set_all_paused(pause);
            o.in_length = put_i32(in_buffer, setup.length, 0);
            o.effect = pause ? ControlOutcome::Effect::PausedAll : ControlOutcome::Effect::ResumedAll;
            return o;
        }
        case ControlRequest::CurrentProtocol: {
            if (auto r = want_out(2); !r) return r.take_error();
            const auto protocol = load_le<std::uint16_t>(out_data.data());
            if (protocol != kStreamProtocol)
                return stall("CURRENT_PROTOCOL " + std::to_string(protocol) + " is not supported (0x0101 is)");
            protocol_selected_ = true;
            o.effect = ControlOutcome::Effect::ProtocolSelected;
            return o;
        }
        case ControlRequest::Null:
            break;
    }
    return fail(MessageErrorType::NotImplementedError,
                "unknown RR USB control request " + std::to_string(setup.request));
}

Result<DeviceEvent> DeviceFunction::on_bulk_out(std::span<const std::byte> transfer) {
    return read_inbound_subpacket(out_, transfer, "USB host");
}

Result<void> DeviceFunction::pause_receive(std::int32_t id, bool paused) {
    if (!out_.contains(id)) return stall("USB stream " + std::to_string(id) + " is not open");
    return out_.queue_notification(id, paused ? Notification::PauseRequest : Notification::ResumeRequest);
}

}  // namespace rr::usb
