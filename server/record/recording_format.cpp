#include "server/record/recording_format.hpp"

#include "core/mcap/mcap_writer.hpp"

namespace rr::server::record {

namespace {

std::span<const std::byte> as_bytes(std::string_view s) { return {reinterpret_cast<const std::byte*>(s.data()), s.size()}; }

RRError file_error(const std::string& path, const RRError& e) { return make_error(e.type, "record: " + path + ": " + e.message); }

}  // namespace

Result<std::uint16_t> FormatFile::add_schema(std::string_view name, std::string_view encoding, std::string_view data) {
    auto id = writer_.add_schema(name, encoding, as_bytes(data));
    if (!id) return fail(file_error(path_, id.error()));
    return *id;
}

Result<std::uint16_t> FormatFile::add_channel(std::uint16_t schema, std::string_view topic, std::string_view message_encoding,
                                              const ChannelMetadata& metadata) {
    auto id = writer_.add_channel(schema, topic, message_encoding, metadata);
    if (!id) return fail(file_error(path_, id.error()));
    return *id;
}

std::uint16_t FormatFile::definition_schema(std::string_view service) const {
    auto it = definitions_.find(std::string(service));
    return it != definitions_.end() ? it->second : root_definition_;
}

Result<void> MessageOut::write(std::uint16_t channel, std::span<const std::byte> data) {
    mcap::MessageView v;
    v.channel_id = channel;
    v.sequence = sequence_++;
    v.log_time = log_ns_;
    v.publish_time = publish_ns_;
    v.data = data;
    if (auto r = writer_.write(v); !r) return fail(file_error(path_, r.error()));
    messages_.fetch_add(1, std::memory_order_relaxed);
    return {};
}

Result<void> RecordingFormat::check_replay_channel(const mcap::Channel& channel) const {
    return fail(MessageErrorType::InvalidArgument, "channel " + channel.topic + ": format " + std::string(name()) + " is not replayed");
}

Result<MessageEntry> RecordingFormat::read_entry(std::span<const std::byte>) const {
    return fail(MessageErrorType::InvalidOperation, "format " + std::string(name()) + " is not replayed");
}

const RecordingFormat* replay_format(const RecordingFormats& formats, std::string_view message_encoding) {
    for (const auto& f : formats)
        if (!f->replay_encoding().empty() && f->replay_encoding() == message_encoding) return f.get();
    return nullptr;
}

}  // namespace rr::server::record
