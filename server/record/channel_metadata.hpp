// The names a recording's MCAP channels carry (docs/recording.md "Recording in the gateway"): the
// metadata keys every channel of a recorded member has, the member kinds, and the `robotraconteur`
// channels' entry format. The recorder writes them and replay reads them from here only.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>

namespace rr::server::record {

/// A channel's metadata: key → value (mcap::Channel::metadata).
using ChannelMetadata = std::map<std::string, std::string>;

/// The metadata keys (values are strings).
namespace channel_key {
inline constexpr const char* device = "device";            ///< the gateway device's name
inline constexpr const char* member = "member";            ///< the member's name
inline constexpr const char* kind = "kind";                ///< member_kind_name()
inline constexpr const char* object_type = "object_type";  ///< the qualified type of the member's object
inline constexpr const char* path = "path";                ///< the object's path below the root ("" = the root)
inline constexpr const char* root_type = "root_type";      ///< the device's root object type
inline constexpr const char* type = "type";                ///< the member's robdef type text (not for events)
inline constexpr const char* period_ms = "period_ms";      ///< a property's polling period
inline constexpr const char* entry_format = "entry_format";  ///< `robotraconteur` channels: kEntryFormat
inline constexpr const char* foxglove = "foxglove";        ///< Foxglove image channels: what they show
}  // namespace channel_key

/// The value of `key` in `metadata` ("" when absent).
inline std::string metadata_value(const ChannelMetadata& metadata, const char* key) {
    auto it = metadata.find(key);
    return it == metadata.end() ? std::string() : it->second;
}

/// The message encoding and schema encoding of a recording's RR channels and service definitions.
inline constexpr std::string_view kRobotRaconteurEncoding = "robotraconteur";
inline constexpr std::string_view kServiceDefinitionSchemaEncoding = "robotraconteur_servicedef";
/// `entry_format` of a `robotraconteur` channel: one RR message entry in message format 4 (wire.md §2).
inline constexpr std::string_view kEntryFormat = "4";

/// What a recorded member is, as its channels' `kind` says.
enum class RecordedKind : std::uint8_t { wire, pipe, event, property };

/// "wire", "pipe", "event", "property".
constexpr std::string_view member_kind_name(RecordedKind k) noexcept {
    switch (k) {
        case RecordedKind::wire: return "wire";
        case RecordedKind::pipe: return "pipe";
        case RecordedKind::event: return "event";
        case RecordedKind::property: return "property";
    }
    return "?";
}

/// The kind a `kind` value names, or nothing.
constexpr std::optional<RecordedKind> member_kind_from_name(std::string_view name) noexcept {
    for (auto k : {RecordedKind::wire, RecordedKind::pipe, RecordedKind::event, RecordedKind::property})
        if (member_kind_name(k) == name) return k;
    return std::nullopt;
}

}  // namespace rr::server::record
