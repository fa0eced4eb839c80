// A device's members as channels (docs/recording.md "Recording in the gateway"): which members a
// request names (the root's or, by path, those of objects below it), the topic and metadata each
// member's channels carry, and what a channel is. The formats map each member and each of its values
// onto channels (formats/json_format.hpp: one `json` channel and a JSON Schema per member;
// formats/foxglove_image_format.hpp: a Foxglove image channel for a standard image member); a Recording
// writes them to MCAP files.
//
// The mapping needs no Recording and no file: a live publisher of a device (e.g. a Foxglove WebSocket
// server) uses it the same way:
//
//     auto members = recorded_members(device, *api, names, {});  // names {}: every wire, pipe and event of the root
//     if (!members) ...;                                                    // InvalidArgument / InvalidState, see below
//     for (const auto& m : *members) {
//         advertise(json_channel(m));                                        // topic, "json", schema name and text
//         if (auto kind = foxglove_image_kind_of(m)) advertise(foxglove_image_channel(m, *kind));
//     }
//     // Then each entry of member i, as a gateway::SharedEntry: a wire value or event from
//     // DeviceMirror::subscribe(m.target->path, m.target->member->name, ...), a pipe packet wrapped in a
//     // PipePacket entry (element 0 = the packet), a property's PropertyGetRes (Recording::subscribe_members
//     // and its poller do exactly this):
//     send(json_message(*api, members[i], shared));                          // that channel's JSON text
//     if (kind) if (auto image = foxglove_image_message(*api, members[i], *kind, shared.entry(), log_ns)) send(*image);
//
// json_message renders a wire value or event through shared.rendered(): the JSON WebSocket's body of the
// same entry, made once for every subscriber and for these channels.
// Thread-safe: the functions keep no state; a member holds shared, immutable types.
#pragma once

#include <chrono>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "base/error/rr_error.hpp"
#include "server/gateway/json_api.hpp"
#include "server/record/channel_metadata.hpp"

namespace rr::server::record {

/// One member of a device mapped to channels: what it is, and what every channel of it carries.
struct RecordedMember {
    using Kind = RecordedKind;
    Kind kind = Kind::wire;
    std::shared_ptr<const gateway::MemberTarget> target;
    std::string topic;         ///< its channels' topic (object_path.hpp channel_topic), e.g. `cam/frames`
    ChannelMetadata metadata;  ///< the keys each of its channels has (channel_metadata.hpp); a format may add its own
};

/// One channel a format maps a member to, as MCAP (and Foxglove's WebSocket protocol) declare it.
struct MappedChannel {
    std::string topic;
    std::string message_encoding;  ///< e.g. "json"
    std::string schema_name;
    std::string schema_encoding;   ///< e.g. "jsonschema"
    std::string schema;            ///< the schema's text
    ChannelMetadata metadata;
};

/// The members `names` names on `device` (connected: its definitions are needed; its configured name
/// begins the topics and is the `device` metadata): a root member by name, a member below the root by
/// path (`Webcams[0].FrameStream`, object_path.hpp). `names` empty: every wire, pipe and event of the
/// root, and every readable property when `property_period` is set. `property_period` also goes into
/// a property's `period_ms` (1000 when unset). Errors (InvalidArgument, "record: members: …"): a member
/// the object does not have, a path that does not follow objrefs, a member of a kind that cannot be
/// mapped (functions, callbacks, objrefs, memories; write-only properties); "record: <type>: nothing to
/// record"; "record: too many members" (over 30000). InvalidState: the device's definitions or root
/// type unknown.
Result<std::vector<RecordedMember>> recorded_members(const std::shared_ptr<gateway::DeviceMirror>& device, const gateway::JsonApi& api,
                                                     const std::vector<std::string>& names, std::chrono::milliseconds property_period);

}  // namespace rr::server::record
