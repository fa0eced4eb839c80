// The `json` format's mapping (docs/recording.md "Recording in the gateway"): one channel per member,
// message encoding `json`, its schema a JSON Schema (json_schema.hpp) named `<object type>.<member>`, so
// that Foxglove and Lichtblick show the values as they are. Each message is the JSON API's mapping
// (docs/json-mapping.md): a wire value {"value", "time"}, an event {"args"}, a pipe packet or a polled
// property {"value"} (or {"error"} for one that does not convert). A null member of an object (an
// absent struct, list, map or varvalue) is left out, since the schema gives every property one type.
// Usable without a Recording (channel_mapping.hpp); the format itself is json_format() (formats.hpp).
#pragma once

#include <string>

#include "server/gateway/shared_entry.hpp"
#include "server/record/channel_mapping.hpp"

namespace rr::server::record {

/// The member's `json` channel: its topic, "json", the schema's name, "jsonschema", the schema's text,
/// the member's metadata.
MappedChannel json_channel(const RecordedMember& member);

/// The message of one entry of `member` on its json channel (a WirePacket, an EventReq, a PipePacket
/// whose first element is the packet, or a property's PropertyGetRes). A wire value's or an event's
/// text is the entry's shared rendering (SharedEntry::rendered, the JSON sockets' push body: made once
/// for all of them) when it holds no null member.
std::string json_message(const gateway::JsonApi& api, const RecordedMember& member, const gateway::SharedEntry& entry);

}  // namespace rr::server::record
