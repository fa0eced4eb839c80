// What a device offers a Foxglove client (docs/foxglove.md "Channels, parameters and services"): one
// channel per wire, pipe and event of its root object (and of the objects below the root that the
// configuration names), a second channel for a standard image member, one parameter per readable
// property, one service per function.
//
// The channels are the recorder's (server/record/channel_mapping.hpp): the members from
// record::recorded_members, each channel from record::json_channel / foxglove_image_channel, each
// message from record::json_message / foxglove_image_message. So a live topic, its schema and its
// messages are exactly a recording's, and a layout made for a recording works live. Parameters and
// services (which recordings do not have) use the same topics (record::channel_topic) and JSON Schemas
// (record/json_schema.hpp).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "base/error/rr_error.hpp"
#include "server/gateway/json_api.hpp"
#include "server/record/channel_mapping.hpp"
#include "server/record/formats/foxglove_image_format.hpp"

namespace rr::server::foxglove {

enum class LiveKind { wire, pipe, event, property, function };

/// One member as Foxglove sees it.
struct LiveMember {
    LiveKind kind = LiveKind::wire;
    std::shared_ptr<const gateway::MemberTarget> target;
    std::string object;       ///< relative path below the root ("" = the root), as the JSON API's `object`
    std::string topic;        ///< channel topic / parameter name / service name: `<device>[/<object>]/<member>`
    std::string schema_name;  ///< channels: the recorder's; services: `<object type>.<member>`
    std::string schema;       ///< JSON Schema text: the message's (channels), the request's (services)
    std::string response_schema;  ///< services: {"return": T}
    bool writable = false;    ///< wires a client may publish to (not readonly); writable properties
    /// Channels: the recorder's member (its json channel's messages come from there).
    std::shared_ptr<const record::RecordedMember> recorded;
    /// The member's Foxglove image channel `<topic>/foxglove` (foxglove.RawImage / CompressedImage);
    /// nothing for its json channel.
    std::optional<record::FoxgloveImageKind> image;
};

/// The members of `device` (connected: its definitions known) at the root and at each of `objects`
/// (relative paths such as `Webcams[0]`). Errors: InvalidState (not connected, definitions unusable),
/// InvalidArgument (an object path that does not resolve, naming it).
Result<std::vector<LiveMember>> device_members(const gateway::JsonApi& api, const std::shared_ptr<gateway::DeviceMirror>& device,
                                               const std::vector<std::string>& objects);

/// The message of one entry (a WirePacket, an EventReq, a PipePacket whose first element is the packet)
/// on `member`'s channel, received at `receive_ns`: the json channel's text, or the image channel's
/// (nothing for a frame Foxglove has no form of).
std::optional<std::string> channel_message(const gateway::JsonApi& api, const LiveMember& member, const gateway::SharedEntry& entry,
                                           std::uint64_t receive_ns);

}  // namespace rr::server::foxglove
