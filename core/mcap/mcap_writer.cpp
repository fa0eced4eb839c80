#include "core/mcap/mcap_writer.hpp"

#include <algorithm>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include "base/codec/endian.hpp"
#include "core/mcap/mcap_compression.hpp"
#include "core/mcap/mcap_record_codec.hpp"

namespace rr::mcap {

using detail::Bytes;

struct McapWriter::State {
    State(Sink& sink_, WriterOptions options_) : sink(sink_), options(std::move(options_)) {}

    Sink& sink;
    WriterOptions options;
    bool opened = false;
    bool closed = false;
    std::optional<RRError> failure;  // first error; every later call refuses

    std::uint64_t offset = 0;     // bytes written to the sink
    std::uint32_t data_crc = 0;   // CRC of every byte before Data End

    std::vector<Schema> schemas;    // id = index + 1
    std::vector<Channel> channels;  // id = index
    std::vector<ChunkIndex> chunk_indexes;
    std::size_t summary_memory = 0;  // memory_of() the schemas, channels and chunk indexes kept for the summary
    Statistics stats;

    // The open chunk.
    Bytes chunk;  // uncompressed records
    std::uint64_t chunk_start_time = 0;
    std::uint64_t chunk_end_time = 0;
    bool chunk_has_messages = false;
    std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> message_indexes;

    detail::ZstdCompressor zstd;
    Bytes compressed;
    Bytes scratch;

    Result<void> guard() const {
        if (failure) return fail(MessageErrorType::InvalidState, "mcap writer failed earlier: " + failure->message);
        if (closed) return fail(MessageErrorType::InvalidState, "mcap writer is closed");
        if (!opened) return fail(MessageErrorType::InvalidState, "mcap writer is not open (call open() first)");
        return {};
    }

    Result<void> failed(Unexpected u) {
        failure = *u.error;
        return u;
    }

    Result<void> emit(std::span<const std::byte> bytes, bool data_section) {
        if (auto r = sink.write(bytes); !r) return failed(r.take_error());
        if (data_section) data_crc = detail::crc32_update(data_crc, bytes);
        offset += bytes.size();
        return {};
    }

    Result<void> write_chunk() {
        if (chunk.empty()) return {};
        if (!chunk_has_messages) {  // only schemas and channels: outside a chunk (mcap_writer.hpp)
            if (auto r = emit(chunk, true); !r) return r;
            chunk.clear();
            if (auto r = sink.flush(); !r) return failed(r.take_error());
            return {};
        }
        std::string_view compression;
        std::span<const std::byte> records = chunk;
        if (options.compression == Compression::Zstd) {
            if (auto r = zstd.compress(chunk, options.zstd_level, compressed); !r) return failed(r.take_error());
            compression = "zstd";
            records = compressed;
        }
        ChunkIndex index;
        index.message_start_time = chunk_has_messages ? chunk_start_time : 0;
        index.message_end_time = chunk_has_messages ? chunk_end_time : 0;
        index.chunk_start_offset = offset;
        index.compression = std::string(compression);
        index.compressed_size = records.size();
        index.uncompressed_size = chunk.size();

        scratch.clear();
        detail::encode_chunk_prefix(scratch, index.message_start_time, index.message_end_time, chunk.size(),
                                    detail::crc32_update(0, chunk), compression, records.size());
        index.chunk_length = scratch.size() + records.size();
        if (auto r = emit(scratch, true); !r) return r;
        if (auto r = emit(records, true); !r) return r;

        scratch.clear();
        std::uint64_t index_start = offset;
        for (const auto& [channel_id, entries] : message_indexes) {
            index.message_index_offsets[channel_id] = index_start + scratch.size();
            detail::encode_message_index(scratch, channel_id, entries);
        }
        index.message_index_length = scratch.size();
        if (auto r = emit(scratch, true); !r) return r;

        summary_memory += memory_of(index);
        chunk_indexes.push_back(std::move(index));
        ++stats.chunk_count;
        chunk.clear();
        message_indexes.clear();
        chunk_has_messages = false;
        // A chunk far over the target (one huge message) would keep its memory for the whole recording.
        if (chunk.capacity() > 4 * options.chunk_size) Bytes().swap(chunk);
        if (compressed.capacity() > 4 * options.chunk_size) Bytes().swap(compressed);
        if (auto r = sink.flush(); !r) return failed(r.take_error());
        return {};
    }

    Result<void> chunk_filled() {
        if (chunk.size() >= options.chunk_size) return write_chunk();
        return {};
    }
};

McapWriter::McapWriter(Sink& sink, WriterOptions options) : s_(std::make_unique<State>(sink, std::move(options))) {}
McapWriter::~McapWriter() = default;

Result<void> McapWriter::open() {
    if (s_->opened || s_->failure) return fail(MessageErrorType::InvalidState, "mcap writer: open() called twice");
    s_->opened = true;
    Bytes out;
    detail::append_magic(out);
    detail::encode_header(out, Header{s_->options.profile, s_->options.library});
    if (auto r = s_->emit(out, true); !r) return r;
    if (auto r = s_->sink.flush(); !r) return s_->failed(r.take_error());
    return {};
}

Result<std::uint16_t> McapWriter::add_schema(std::string_view name, std::string_view encoding,
                                             std::span<const std::byte> data) {
    if (auto r = s_->guard(); !r) return r.take_error();
    if (s_->schemas.size() >= 65535)
        return fail(MessageErrorType::InvalidArgument, "mcap writer: more than 65535 schemas");
    constexpr auto kMax32 = std::numeric_limits<std::uint32_t>::max();
    if (name.size() > kMax32 || encoding.size() > kMax32 || data.size() > kMax32)
        return fail(MessageErrorType::InvalidArgument, "mcap writer: schema name, encoding or data over 4 GiB");
    Schema schema{static_cast<std::uint16_t>(s_->schemas.size() + 1), std::string(name), std::string(encoding),
                  Bytes(data.begin(), data.end())};
    detail::encode_schema(s_->chunk, schema);
    s_->summary_memory += memory_of(schema);
    s_->schemas.push_back(std::move(schema));
    ++s_->stats.schema_count;
    if (auto r = s_->chunk_filled(); !r) return r.take_error();
    return s_->schemas.back().id;
}

Result<std::uint16_t> McapWriter::add_channel(std::uint16_t schema_id, std::string_view topic,
                                              std::string_view message_encoding,
                                              const std::map<std::string, std::string>& metadata) {
    if (auto r = s_->guard(); !r) return r.take_error();
    if (schema_id > s_->schemas.size())
        return fail(MessageErrorType::InvalidArgument,
                    "mcap writer: schema id " + std::to_string(schema_id) + " was not added");
    if (s_->channels.size() > 65535)
        return fail(MessageErrorType::InvalidArgument, "mcap writer: more than 65536 channels");
    std::uint64_t map_bytes = 0;
    for (const auto& [k, v] : metadata) map_bytes += 8 + k.size() + v.size();
    constexpr auto kMax32 = std::numeric_limits<std::uint32_t>::max();
    if (topic.size() > kMax32 || message_encoding.size() > kMax32 || map_bytes > kMax32)
        return fail(MessageErrorType::InvalidArgument, "mcap writer: channel topic, encoding or metadata over 4 GiB");
    Channel channel{static_cast<std::uint16_t>(s_->channels.size()), schema_id, std::string(topic),
                    std::string(message_encoding), metadata};
    detail::encode_channel(s_->chunk, channel);
    s_->summary_memory += memory_of(channel);
    s_->channels.push_back(std::move(channel));
    ++s_->stats.channel_count;
    if (auto r = s_->chunk_filled(); !r) return r.take_error();
    return s_->channels.back().id;
}

Result<void> McapWriter::write(const MessageView& m) {
    if (auto r = s_->guard(); !r) return r;
    if (m.channel_id >= s_->channels.size())
        return fail(MessageErrorType::InvalidArgument,
                    "mcap writer: channel id " + std::to_string(m.channel_id) + " was not added");
    auto& s = *s_;
    s.message_indexes[m.channel_id].emplace_back(m.log_time, s.chunk.size());
    detail::encode_message(s.chunk, m.channel_id, m.sequence, m.log_time, m.publish_time, m.data);
    if (!s.chunk_has_messages) {
        s.chunk_start_time = s.chunk_end_time = m.log_time;
        s.chunk_has_messages = true;
    } else {
        s.chunk_start_time = std::min(s.chunk_start_time, m.log_time);
        s.chunk_end_time = std::max(s.chunk_end_time, m.log_time);
    }
    if (s.stats.message_count == 0) {
        s.stats.message_start_time = s.stats.message_end_time = m.log_time;
    } else {
        s.stats.message_start_time = std::min(s.stats.message_start_time, m.log_time);
        s.stats.message_end_time = std::max(s.stats.message_end_time, m.log_time);
    }
    ++s.stats.message_count;
    ++s.stats.channel_message_counts[m.channel_id];
    return s.chunk_filled();
}

Result<void> McapWriter::flush() {
    if (auto r = s_->guard(); !r) return r;
    if (s_->chunk.empty()) {
        if (auto r = s_->sink.flush(); !r) return s_->failed(r.take_error());
        return {};
    }
    return s_->write_chunk();
}

Result<void> McapWriter::close() {
    if (auto r = s_->guard(); !r) return r;
    auto& s = *s_;
    if (auto r = s.write_chunk(); !r) return r;

    Bytes out;
    detail::encode_data_end(out, s.data_crc);
    if (auto r = s.emit(out, true); !r) return r;

    // Summary: groups by opcode, each group's place noted for its Summary Offset record.
    const std::uint64_t summary_start = s.offset;
    out.clear();
    struct Group {
        Opcode op;
        std::uint64_t start, length;
    };
    std::vector<Group> groups;
    auto group = [&](Opcode op, auto&& encode_all) {
        std::size_t begin = out.size();
        encode_all();
        if (out.size() > begin) groups.push_back({op, summary_start + begin, out.size() - begin});
    };
    group(Opcode::Schema, [&] { for (const auto& x : s.schemas) detail::encode_schema(out, x); });
    group(Opcode::Channel, [&] { for (const auto& x : s.channels) detail::encode_channel(out, x); });
    group(Opcode::ChunkIndex, [&] { for (const auto& x : s.chunk_indexes) detail::encode_chunk_index(out, x); });
    group(Opcode::Statistics, [&] { detail::encode_statistics(out, s.stats); });
    const std::uint64_t summary_offset_start = summary_start + out.size();
    for (const auto& g : groups) detail::encode_summary_offset(out, g.op, g.start, g.length);
    detail::encode_footer_prefix(out, summary_start, summary_offset_start);
    std::uint32_t summary_crc = detail::crc32_update(0, out);
    std::byte crc[4];
    store_le<std::uint32_t>(crc, summary_crc);
    out.insert(out.end(), crc, crc + 4);
    detail::append_magic(out);
    if (auto r = s.emit(out, false); !r) return r;
    if (auto r = s.sink.flush(); !r) return s.failed(r.take_error());
    s.closed = true;
    return {};
}

std::uint64_t McapWriter::bytes_written() const noexcept { return s_->offset; }
std::size_t McapWriter::summary_memory_bytes() const noexcept { return s_->summary_memory; }
const Statistics& McapWriter::statistics() const noexcept { return s_->stats; }
bool McapWriter::is_open() const noexcept { return s_->opened && !s_->closed && !s_->failure; }
bool McapWriter::is_closed() const noexcept { return s_->closed; }

}  // namespace rr::mcap
