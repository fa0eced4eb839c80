// The `robotraconteur` format (docs/recording.md): each recorded entry as one RR message entry in
// message format 4 (wire.md §2), the bytes the gateway sends its native clients (encoded once, shared).
// Its channels refer to the service definition of their member's object. Replay plays these channels.
#include "base/message/message_reader.hpp"
#include "base/message/message_writer.hpp"
#include "server/record/formats/formats.hpp"

namespace rr::server::record {
namespace {

class RobotRaconteurEncoder : public FormatEncoder {
public:
    explicit RobotRaconteurEncoder(const FormatContext& context) : context_(context) {}

    Result<void> open_file(FormatFile& file) override {
        channels_.clear();
        for (const auto& m : context_.members) {
            auto metadata = m.metadata;
            metadata[channel_key::entry_format] = std::string(kEntryFormat);
            auto id = file.add_channel(file.definition_schema(m.target->service->name), m.topic, kRobotRaconteurEncoding, metadata);
            if (!id) return id.take_error();
            channels_.push_back(*id);
        }
        return {};
    }

    Result<void> write(const RecordedEntry& e, MessageOut& out) override {
        // The bytes native clients are sent (cached in the SharedEntry, made once).
        auto bytes = e.entry.bytes(4);
        if (!bytes) return {};
        return out.write(channels_[e.member], *bytes);
    }

private:
    const FormatContext& context_;
    std::vector<std::uint16_t> channels_;  // per member
};

class RobotRaconteurFormat : public RecordingFormat {
public:
    std::string_view name() const noexcept override { return kRobotRaconteurEncoding; }
    std::unique_ptr<FormatEncoder> encoder(const FormatContext& context) const override {
        return std::make_unique<RobotRaconteurEncoder>(context);
    }

    std::string_view replay_encoding() const noexcept override { return kRobotRaconteurEncoding; }

    Result<void> check_replay_channel(const mcap::Channel& ch) const override {
        auto it = ch.metadata.find(channel_key::entry_format);
        if (it == ch.metadata.end())
            return fail(MessageErrorType::InvalidArgument, "channel " + ch.topic + ": no entry_format (expected \"" +
                                                               std::string(kEntryFormat) + "\": RR message format 4)");
        if (it->second != kEntryFormat)
            return fail(MessageErrorType::InvalidArgument, "channel " + ch.topic + ": entry_format \"" + it->second +
                                                               "\" is not one this gateway reads (\"" + std::string(kEntryFormat) +
                                                               "\": RR message format 4)");
        return {};
    }

    // One entry, decoded inside a format-4 message of its own, as a session would receive it: standard
    // string-table codes (in files recorded before entries were kept free of them) are resolved, not
    // replayed.
    Result<MessageEntry> read_entry(std::span<const std::byte> bytes) const override {
        Message m;
        m.version = 4;
        std::vector<std::byte> out;
        if (auto r = encode_message(m, bytes, out); !r) return r.take_error();
        DecodeContext plain;
        plain.keep_string_table_codes = false;
        auto decoded = decode_message(SharedBytes::adopt(std::move(out)), {}, &plain);
        if (!decoded) return decoded.take_error();
        if (decoded->entries.size() != 1) return fail(MessageErrorType::DataSerializationError, "not one message entry");
        return std::move(decoded->entries[0]);
    }
};

}  // namespace

std::shared_ptr<const RecordingFormat> robotraconteur_format() { return std::make_shared<RobotRaconteurFormat>(); }

}  // namespace rr::server::record
