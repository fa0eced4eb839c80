// The `foxglove_image` format: extra `json` channels that Foxglove's / Lichtblick's Image panel shows
// (docs/recording.md "Opening a recording in Foxglove or Lichtblick"). With `json` and
// RecordingSpec::foxglove_images, a recorded member whose value is a standard image
// (com.robotraconteur.image.Image or CompressedImage) also gets a channel `<device>/<member>/foxglove`
// whose schema is named foxglove.RawImage or foxglove.CompressedImage and whose messages have those
// schemas' fields, the pixel bytes in base64. The format itself is foxglove_image_format()
// (formats.hpp); these are its parts, the member-level ones usable without a Recording
// (channel_mapping.hpp).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "core/value/value.hpp"
#include "robdef/service_definition.hpp"
#include "robdef/type_lookup.hpp"
#include "server/record/channel_mapping.hpp"

namespace rr::server::record {

enum class FoxgloveImageKind { raw, compressed };

/// Which Foxglove image a value of `type` becomes: a single (not array, not container) value of
/// com.robotraconteur.image.Image (raw) or CompressedImage (compressed); nothing for anything else.
std::optional<FoxgloveImageKind> foxglove_image_kind(const robdef::TypeDefinition& type,
                                                     const robdef::TypeLookup& lookup, std::string_view context_service);

/// "foxglove.RawImage" or "foxglove.CompressedImage": the schema name Foxglove's Image panel looks for.
std::string_view foxglove_schema_name(FoxgloveImageKind kind);

/// The channel's JSON Schema (our own text of the fields of the foxglove schema of that name; data is a
/// base64 string, `contentEncoding: base64`, timestamp {sec, nsec}).
nlohmann::json foxglove_image_schema(FoxgloveImageKind kind);

/// Foxglove's raw image encoding name for an RR ImageEncoding value (rgb888 → "rgb8", mono16 → "mono16",
/// depth_u16 → "16UC1", bayer_rggb8888 → "bayer_rggb8", ...); nothing for the encodings Foxglove has no
/// equivalent of (rgba16_16_16_16, mono32, floating-point, the other depth formats, freeform, ...).
std::optional<std::string_view> foxglove_raw_encoding(std::int64_t rr_encoding);

/// The Foxglove message for one recorded image: `image` is the value as unpacked from the received
/// element (unpack_value: its `data` bytes shared with the element, not copied), read once into the
/// message. `timestamp` is the image's image_info.data_header.ts when it lies within a day of `log_ns` (a
/// device clock on the Unix epoch), else `log_ns`; frame_id is "". Nothing when the value is null or
/// malformed (`data` not a uint8 array), a raw image's encoding has no Foxglove equivalent, or a
/// compressed image's bytes are not JPEG, PNG or WebP.
std::optional<std::string> foxglove_image_message(FoxgloveImageKind kind, const Value& image, std::uint64_t log_ns);

/// The Foxglove image `member`'s values become (foxglove_image_kind of its type); nothing for an event
/// or a member of another type.
std::optional<FoxgloveImageKind> foxglove_image_kind_of(const RecordedMember& member);

/// The member's Foxglove image channel: topic `<member topic>/foxglove`, "json", foxglove_schema_name,
/// "jsonschema", foxglove_image_schema's text; the member's metadata and `foxglove` (what the channel
/// shows, in words).
MappedChannel foxglove_image_channel(const RecordedMember& member, FoxgloveImageKind kind);

/// The message of one entry of `member` on that channel (a WirePacket, a PipePacket or a property's
/// PropertyGetRes), its element unpacked once (its pixel bytes shared with the entry, not copied) and
/// read into the message; nothing when the entry holds no image the channel shows (see above).
std::optional<std::string> foxglove_image_message(const gateway::JsonApi& api, const RecordedMember& member, FoxgloveImageKind kind,
                                                  const MessageEntry& entry, std::uint64_t log_ns);

}  // namespace rr::server::record
