// A recording format (docs/architecture.md "Recording formats"): what a recording writes for its
// members besides the file itself. A format adds its schemas and one channel per member it takes to
// each new file, turns each recorded entry into messages on those channels, and, if replay plays its
// channels, reads a message back into the entry. Recording (recording.hpp) runs every format the spec
// enables the same way and knows none of them; the built-in ones are registered in formats/formats.cpp.
//
// Threads: a format's encoder is used by its recording's writer thread only.
#pragma once

#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "base/error/rr_error.hpp"
#include "core/mcap/mcap_records.hpp"
#include "base/message/message.hpp"
#include "server/gateway/json_api.hpp"
#include "server/gateway/shared_entry.hpp"
#include "server/record/channel_mapping.hpp"
#include "server/record/recording_spec.hpp"

namespace rr::mcap {
class McapWriter;
}

namespace rr::server::record {

/// What a format's encoder is made with: the recording's spec, its members (indexed as
/// RecordedEntry::member) and the JSON API (for the JSON mapping). All outlive the encoder.
struct FormatContext {
    const RecordingSpec& spec;
    const std::vector<RecordedMember>& members;
    const gateway::JsonApi& api;
};

/// A new MCAP file as a format adds to it. Errors name the file ("record: <path>: …").
class FormatFile {
public:
    FormatFile(mcap::McapWriter& writer, const std::string& path, const std::map<std::string, std::uint16_t>& definitions,
               std::uint16_t root_definition)
        : writer_(writer), path_(path), definitions_(definitions), root_definition_(root_definition) {}

    /// A schema (its id in this file). `encoding`: e.g. "jsonschema".
    Result<std::uint16_t> add_schema(std::string_view name, std::string_view encoding, std::string_view data);
    /// A channel (its id in this file) of `schema` (0: none).
    Result<std::uint16_t> add_channel(std::uint16_t schema, std::string_view topic, std::string_view message_encoding,
                                      const ChannelMetadata& metadata);
    /// The schema holding the device's service definition `service` (every file holds all of them, encoding
    /// robotraconteur_servicedef); the root object's definition when `service` is not among them.
    std::uint16_t definition_schema(std::string_view service) const;

private:
    mcap::McapWriter& writer_;
    const std::string& path_;
    const std::map<std::string, std::uint16_t>& definitions_;
    std::uint16_t root_definition_;
};

/// One entry the recording took (a wire value, an event, a pipe packet, a polled property's reply).
struct RecordedEntry {
    std::uint16_t member;              ///< index into FormatContext::members
    const gateway::SharedEntry& entry;
    std::uint64_t log_ns;              ///< the gateway's receive time, ns since the Unix epoch
};

/// Where an encoder writes an entry's messages: the times and a sequence number are the recording's
/// (one counter per format and member, kept across files). Errors name the file.
class MessageOut {
public:
    MessageOut(mcap::McapWriter& writer, const std::string& path, std::uint64_t log_ns, std::uint64_t publish_ns,
               std::uint32_t& sequence, std::atomic<std::uint64_t>& messages)
        : writer_(writer), path_(path), log_ns_(log_ns), publish_ns_(publish_ns), sequence_(sequence), messages_(messages) {}

    Result<void> write(std::uint16_t channel, std::span<const std::byte> data);
    Result<void> write(std::uint16_t channel, std::string_view text) {
        return write(channel, std::span<const std::byte>(reinterpret_cast<const std::byte*>(text.data()), text.size()));
    }

private:
    mcap::McapWriter& writer_;
    const std::string& path_;
    std::uint64_t log_ns_, publish_ns_;
    std::uint32_t& sequence_;
    std::atomic<std::uint64_t>& messages_;
};

/// One recording's writer of one format.
class FormatEncoder {
public:
    virtual ~FormatEncoder() = default;
    /// A new file is open: this format's schemas and channels go into it (the previous file's ids are gone).
    virtual Result<void> open_file(FormatFile& file) = 0;
    /// The messages `entry` becomes on this format's channels (none for a member it has no channel for).
    /// An entry it cannot encode is left out; errors are the file's (MessageOut::write).
    virtual Result<void> write(const RecordedEntry& entry, MessageOut& out) = 0;
};

class RecordingFormat {
public:
    virtual ~RecordingFormat() = default;
    /// Its name: the `encoding` value of a spec that asks for it (RecordingSpec::encodings), e.g. "json".
    virtual std::string_view name() const noexcept = 0;
    /// Whether `encoding` may name it; false for a format that comes with another one (foxglove_image
    /// comes with json and RecordingSpec::foxglove_images).
    virtual bool is_encoding() const noexcept { return true; }
    /// Whether a recording of `spec` writes it (by default: when its name is among the spec's encodings).
    virtual bool enabled(const RecordingSpec& spec) const { return spec.encodes(name()); }
    /// The encoder of one recording.
    virtual std::unique_ptr<FormatEncoder> encoder(const FormatContext& context) const = 0;

    // --- replay (replay_device.hpp): only a format whose channels hold the device's entries exactly ---

    /// The message encoding of the channels replay plays from ("" = none of this format's).
    virtual std::string_view replay_encoding() const noexcept { return {}; }
    /// Checks such a channel before anything is played (e.g. its entry format). Errors: InvalidArgument.
    virtual Result<void> check_replay_channel(const mcap::Channel& channel) const;
    /// The entry one recorded message holds. Errors: DataSerializationError (malformed).
    virtual Result<MessageEntry> read_entry(std::span<const std::byte> message) const;
};

using RecordingFormats = std::vector<std::shared_ptr<const RecordingFormat>>;

/// The formats rr-gateway and `rr record` write: json, robotraconteur, foxglove_image
/// (formats/formats.cpp, where a new one is registered).
const RecordingFormats& builtin_recording_formats();

/// The format of `formats` that replay plays channels of `message_encoding` from, or nullptr.
const RecordingFormat* replay_format(const RecordingFormats& formats, std::string_view message_encoding);

}  // namespace rr::server::record
