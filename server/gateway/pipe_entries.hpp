// Building and reading the pipe entries the gateway sends and receives as a pipe endpoint of its own
// (wire.md §6.7): PipeConnectReq / PipeDisconnectReq, PipePacket (one element per endpoint, named by
// its index, holding `packetnumber`, `packet` and an optional `requestack`), PipePacketRet (elements
// numbered by the index, holding the acknowledged packet number).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "base/message/message.hpp"

namespace rr::server::gateway {

/// A pipe index written as an element name ("3", "-1"); nullopt when `s` is not a decimal int32.
std::optional<std::int32_t> parse_pipe_index(std::string_view s);
/// The entry's `index` element (PipeConnectRet, PipeClosed, …); −1 when it has none.
std::int32_t entry_pipe_index(const MessageEntry& e);

/// PipeConnectReq for index −1 (the device chooses), with `unreliable` 1 when asked.
MessageEntry pipe_connect_request(std::string path, std::string member, bool unreliable);
/// PipeDisconnectReq for `index`.
MessageEntry pipe_disconnect_request(std::string path, std::string member, std::int32_t index);
/// A PipePacket entry carrying one packet (`packet` is renamed "packet"); metadata "unreliable\n" for
/// an unreliable endpoint.
MessageEntry pipe_packet_entry(std::string path, std::string member, std::int32_t index, std::uint32_t number,
                               MessageElement packet, bool request_ack, bool unreliable);

/// One packet element of a PipePacket: its number, its `packet` child (moved out of `el`) and whether
/// the sender asked for an acknowledgement. nullopt when `el` lacks `packetnumber` or `packet`.
struct ReceivedPipePacket {
    std::uint32_t number = 0;
    MessageElement packet;
    bool request_ack = false;
};
std::optional<ReceivedPipePacket> take_pipe_packet(MessageElement& el);
/// The acknowledgement element of a PipePacketRet for packet `number` on endpoint `index`.
MessageElement pipe_ack_element(std::int32_t index, std::uint32_t number);

}  // namespace rr::server::gateway
