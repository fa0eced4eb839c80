// What a device offers a Foxglove client (docs/foxglove.md "Channels, parameters and services"): one
// channel per wire, pipe and event of its root object (and of the objects below the root that the
// configuration names), one parameter per readable property, one service per function.
//
// The channels are those a recording writes (docs/recording.md): the same topics
// (record::channel_topic), the `json` encoding with the same JSON Schemas (record/json_schema.hpp:
// wire_message_schema, value_message_schema, event_message_schema) and the same schema names
// (`<object type>.<member>`), so a layout made for a recording works live. This file is the seam to
// the recorder's mapping: it calls the recorder's functions and adds nothing of its own to a channel.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/error/rr_error.hpp"
#include "server/gateway/json_api.hpp"
#include "server/record/foxglove_image.hpp"

namespace rr::server::foxglove {

enum class LiveKind { wire, pipe, event, property, function };

/// One member as Foxglove sees it.
struct LiveMember {
    LiveKind kind = LiveKind::wire;
    std::shared_ptr<const gateway::MemberTarget> target;
    std::string object;       ///< relative path below the root ("" = the root), as the JSON API's `object`
    std::string topic;        ///< channel topic / parameter name / service name: `<device>[/<object>]/<member>`
    std::string schema_name;  ///< `<object type>.<member>`
    std::string schema;       ///< JSON Schema text: the message's (channels), the request's (services)
    std::string response_schema;  ///< services: {"return": T}
    bool writable = false;    ///< wires and pipes a client may publish to (not readonly); writable properties
    /// A standard image wire's or pipe's second channel `<topic>/foxglove` (foxglove.RawImage /
    /// CompressedImage, as recordings have: record/foxglove_image.hpp); nothing for the member's own.
    std::optional<record::FoxgloveImageKind> image;
};

/// The members of `device` (connected: its definitions known) at the root and at each of `objects`
/// (relative paths such as `Webcams[0]`). Errors: InvalidState (not connected, definitions unusable),
/// InvalidArgument (an object path that does not resolve, naming it).
Result<std::vector<LiveMember>> device_members(const gateway::JsonApi& api, const std::shared_ptr<gateway::DeviceMirror>& device,
                                               const std::vector<std::string>& objects);

/// The message a wire value or event is on its channel: the JSON API's push body of the value
/// ({"time", "value"} / {"args"}), which the recorder's json channels hold too.
std::string entry_message(const gateway::JsonApi& api, const MessageEntry& entry, const LiveMember& member);
/// A pipe packet's message: {"value": …} (or {"error": …} for a packet that does not fit its type).
std::string packet_message(const gateway::JsonApi& api, const MessageElement& packet, const LiveMember& member);
/// An image channel's message for the value `element` (a wire's "packet", a pipe packet), received at
/// `receive_ns`: the recorder's foxglove_image_message; nothing for a frame Foxglove has no form of.
std::optional<std::string> image_message(const gateway::JsonApi& api, const MessageElement& element, const LiveMember& member,
                                         std::uint64_t receive_ns);

}  // namespace rr::server::foxglove
