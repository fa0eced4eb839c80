#include "core/mcap/mcap_record_codec.hpp"

#include <zlib.h>

#include <algorithm>
#include <optional>

#include "base/codec/byte_reader.hpp"
#include "base/codec/byte_writer.hpp"

namespace rr::mcap::detail {
namespace {

// Starts a record; returns where its content length goes, patched by end_record.
std::size_t begin_record(Bytes& out, Opcode op) {
    out.push_back(static_cast<std::byte>(op));
    std::size_t at = out.size();
    out.resize(out.size() + 8);
    return at;
}

void end_record(Bytes& out, std::size_t length_at) {
    store_le<std::uint64_t>(out.data() + length_at, out.size() - length_at - 8);
}

void put_string(ByteWriter& w, std::string_view s) {
    w.write_u32(static_cast<std::uint32_t>(s.size()));
    w.write_string(s);
}

void put_string_map(ByteWriter& w, const std::map<std::string, std::string>& m) {
    std::uint64_t bytes = 0;
    for (const auto& [k, v] : m) bytes += 8 + k.size() + v.size();
    w.write_u32(static_cast<std::uint32_t>(bytes));
    for (const auto& [k, v] : m) {
        put_string(w, k);
        put_string(w, v);
    }
}

void put_u16_u64_map(ByteWriter& w, const std::map<std::uint16_t, std::uint64_t>& m) {
    w.write_u32(static_cast<std::uint32_t>(m.size() * 10));
    for (const auto& [k, v] : m) {
        w.write_u16(k);
        w.write_u64(v);
    }
}

// Reads fields in order; the first failure is kept and every later read returns a default value
// without touching the bytes, so a decoder reads straight through and checks ok() once.
class FieldReader {
public:
    explicit FieldReader(std::span<const std::byte> content) : r_(content) {}

    template <class T>
    T integer(const char* name) {
        if (error_) return T{};
        auto v = r_.read<T>();
        if (!v) return failed<T>(name, v.error());
        return *v;
    }
    std::uint8_t u8(const char* n) { return integer<std::uint8_t>(n); }
    std::uint16_t u16(const char* n) { return integer<std::uint16_t>(n); }
    std::uint32_t u32(const char* n) { return integer<std::uint32_t>(n); }
    std::uint64_t u64(const char* n) { return integer<std::uint64_t>(n); }

    std::span<const std::byte> view(std::uint64_t n, const char* name) {
        if (error_) return {};
        if (n > r_.remaining()) {
            fail_with(name, "length " + std::to_string(n) + " exceeds the " + std::to_string(r_.remaining()) +
                                " bytes left in the record");
            return {};
        }
        return *r_.take(static_cast<std::size_t>(n));
    }
    std::string string(const char* name) {
        auto n = u32(name);
        auto s = view(n, name);
        return std::string(reinterpret_cast<const char*>(s.data()), s.size());
    }
    Bytes bytes_u32(const char* name) {
        auto n = u32(name);
        auto s = view(n, name);
        return Bytes(s.begin(), s.end());
    }
    std::span<const std::byte> view_u64(const char* name) { return view(u64(name), name); }
    std::span<const std::byte> rest() { return error_ ? std::span<const std::byte>{} : view(r_.remaining(), "data"); }

    std::map<std::string, std::string> string_map(const char* name) {
        std::map<std::string, std::string> m;
        FieldReader inner(view(u32(name), name));
        while (!error_ && !inner.r_.at_end() && !inner.error_) {
            auto k = inner.string(name);
            auto v = inner.string(name);
            if (!inner.error_) m[std::move(k)] = std::move(v);
        }
        adopt(inner);
        return m;
    }
    std::map<std::uint16_t, std::uint64_t> u16_u64_map(const char* name) {
        std::map<std::uint16_t, std::uint64_t> m;
        FieldReader inner(view(u32(name), name));
        while (!error_ && !inner.r_.at_end() && !inner.error_) {
            auto k = inner.u16(name);
            auto v = inner.u64(name);
            if (!inner.error_) m[k] = v;
        }
        adopt(inner);
        return m;
    }
    Result<void> result() const {
        if (error_) return fail(MessageErrorType::DataSerializationError, *error_);
        return {};
    }

private:
    template <class T>
    T failed(const char* name, const RRError& e) {
        fail_with(name, e.message);
        return T{};
    }
    void fail_with(const char* name, const std::string& why) {
        if (!error_) error_ = std::string(name) + ": " + why;
    }
    void adopt(const FieldReader& inner) {
        if (inner.error_ && !error_) error_ = inner.error_;
    }

    ByteReader r_;
    std::optional<std::string> error_;
};

template <class T>
Result<T> finish(const FieldReader& f, T value) {
    if (auto r = f.result(); !r) return r.take_error();
    return value;
}

}  // namespace

void append_magic(Bytes& out) {
    for (auto b : kMagic) out.push_back(static_cast<std::byte>(b));
}

void encode_header(Bytes& out, const Header& header) {
    auto at = begin_record(out, Opcode::Header);
    ByteWriter w(out);
    put_string(w, header.profile);
    put_string(w, header.library);
    end_record(out, at);
}

void encode_schema(Bytes& out, const Schema& schema) {
    auto at = begin_record(out, Opcode::Schema);
    ByteWriter w(out);
    w.write_u16(schema.id);
    put_string(w, schema.name);
    put_string(w, schema.encoding);
    w.write_u32(static_cast<std::uint32_t>(schema.data.size()));
    w.write_bytes(schema.data);
    end_record(out, at);
}

void encode_channel(Bytes& out, const Channel& channel) {
    auto at = begin_record(out, Opcode::Channel);
    ByteWriter w(out);
    w.write_u16(channel.id);
    w.write_u16(channel.schema_id);
    put_string(w, channel.topic);
    put_string(w, channel.message_encoding);
    put_string_map(w, channel.metadata);
    end_record(out, at);
}

void encode_message(Bytes& out, std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time,
                    std::uint64_t publish_time, std::span<const std::byte> data) {
    auto at = begin_record(out, Opcode::Message);
    ByteWriter w(out);
    w.write_u16(channel_id);
    w.write_u32(sequence);
    w.write_u64(log_time);
    w.write_u64(publish_time);
    w.write_bytes(data);
    end_record(out, at);
}

void encode_chunk_prefix(Bytes& out, std::uint64_t start_time, std::uint64_t end_time,
                         std::uint64_t uncompressed_size, std::uint32_t uncompressed_crc,
                         std::string_view compression, std::uint64_t records_size) {
    out.push_back(static_cast<std::byte>(Opcode::Chunk));
    ByteWriter w(out);
    w.write_u64(8 + 8 + 8 + 4 + 4 + compression.size() + 8 + records_size);
    w.write_u64(start_time);
    w.write_u64(end_time);
    w.write_u64(uncompressed_size);
    w.write_u32(uncompressed_crc);
    put_string(w, compression);
    w.write_u64(records_size);
}

void encode_message_index(Bytes& out, std::uint16_t channel_id,
                          const std::vector<std::pair<std::uint64_t, std::uint64_t>>& entries) {
    auto at = begin_record(out, Opcode::MessageIndex);
    ByteWriter w(out);
    w.write_u16(channel_id);
    w.write_u32(static_cast<std::uint32_t>(entries.size() * 16));
    for (const auto& [time, offset] : entries) {
        w.write_u64(time);
        w.write_u64(offset);
    }
    end_record(out, at);
}

void encode_chunk_index(Bytes& out, const ChunkIndex& index) {
    auto at = begin_record(out, Opcode::ChunkIndex);
    ByteWriter w(out);
    w.write_u64(index.message_start_time);
    w.write_u64(index.message_end_time);
    w.write_u64(index.chunk_start_offset);
    w.write_u64(index.chunk_length);
    put_u16_u64_map(w, index.message_index_offsets);
    w.write_u64(index.message_index_length);
    put_string(w, index.compression);
    w.write_u64(index.compressed_size);
    w.write_u64(index.uncompressed_size);
    end_record(out, at);
}

void encode_statistics(Bytes& out, const Statistics& s) {
    auto at = begin_record(out, Opcode::Statistics);
    ByteWriter w(out);
    w.write_u64(s.message_count);
    w.write_u16(s.schema_count);
    w.write_u32(s.channel_count);
    w.write_u32(s.attachment_count);
    w.write_u32(s.metadata_count);
    w.write_u32(s.chunk_count);
    w.write_u64(s.message_start_time);
    w.write_u64(s.message_end_time);
    put_u16_u64_map(w, s.channel_message_counts);
    end_record(out, at);
}

void encode_summary_offset(Bytes& out, Opcode group, std::uint64_t start, std::uint64_t length) {
    auto at = begin_record(out, Opcode::SummaryOffset);
    ByteWriter w(out);
    w.write_u8(static_cast<std::uint8_t>(group));
    w.write_u64(start);
    w.write_u64(length);
    end_record(out, at);
}

void encode_data_end(Bytes& out, std::uint32_t data_section_crc) {
    auto at = begin_record(out, Opcode::DataEnd);
    ByteWriter(out).write_u32(data_section_crc);
    end_record(out, at);
}

void encode_footer_prefix(Bytes& out, std::uint64_t summary_start, std::uint64_t summary_offset_start) {
    out.push_back(static_cast<std::byte>(Opcode::Footer));
    ByteWriter w(out);
    w.write_u64(20);
    w.write_u64(summary_start);
    w.write_u64(summary_offset_start);
}

Result<Header> decode_header(std::span<const std::byte> content) {
    FieldReader f(content);
    Header h;
    h.profile = f.string("profile");
    h.library = f.string("library");
    return finish(f, std::move(h));
}

Result<Schema> decode_schema(std::span<const std::byte> content) {
    FieldReader f(content);
    Schema s;
    s.id = f.u16("id");
    s.name = f.string("name");
    s.encoding = f.string("encoding");
    s.data = f.bytes_u32("data");
    return finish(f, std::move(s));
}

Result<Channel> decode_channel(std::span<const std::byte> content) {
    FieldReader f(content);
    Channel c;
    c.id = f.u16("id");
    c.schema_id = f.u16("schema_id");
    c.topic = f.string("topic");
    c.message_encoding = f.string("message_encoding");
    c.metadata = f.string_map("metadata");
    return finish(f, std::move(c));
}

Result<Message> decode_message(std::span<const std::byte> content) {
    FieldReader f(content);
    Message m;
    m.channel_id = f.u16("channel_id");
    m.sequence = f.u32("sequence");
    m.log_time = f.u64("log_time");
    m.publish_time = f.u64("publish_time");
    auto data = f.rest();
    m.data.assign(data.begin(), data.end());
    return finish(f, std::move(m));
}

Result<ChunkRecord> decode_chunk(std::span<const std::byte> content) {
    FieldReader f(content);
    ChunkRecord c;
    c.message_start_time = f.u64("message_start_time");
    c.message_end_time = f.u64("message_end_time");
    c.uncompressed_size = f.u64("uncompressed_size");
    c.uncompressed_crc = f.u32("uncompressed_crc");
    c.compression = f.string("compression");
    c.records = f.view_u64("records");
    return finish(f, std::move(c));
}

Result<ChunkIndex> decode_chunk_index(std::span<const std::byte> content) {
    FieldReader f(content);
    ChunkIndex c;
    c.message_start_time = f.u64("message_start_time");
    c.message_end_time = f.u64("message_end_time");
    c.chunk_start_offset = f.u64("chunk_start_offset");
    c.chunk_length = f.u64("chunk_length");
    c.message_index_offsets = f.u16_u64_map("message_index_offsets");
    c.message_index_length = f.u64("message_index_length");
    c.compression = f.string("compression");
    c.compressed_size = f.u64("compressed_size");
    c.uncompressed_size = f.u64("uncompressed_size");
    return finish(f, std::move(c));
}

Result<Statistics> decode_statistics(std::span<const std::byte> content) {
    FieldReader f(content);
    Statistics s;
    s.message_count = f.u64("message_count");
    s.schema_count = f.u16("schema_count");
    s.channel_count = f.u32("channel_count");
    s.attachment_count = f.u32("attachment_count");
    s.metadata_count = f.u32("metadata_count");
    s.chunk_count = f.u32("chunk_count");
    s.message_start_time = f.u64("message_start_time");
    s.message_end_time = f.u64("message_end_time");
    s.channel_message_counts = f.u16_u64_map("channel_message_counts");
    return finish(f, std::move(s));
}

Result<FooterRecord> decode_footer(std::span<const std::byte> content) {
    FieldReader f(content);
    FooterRecord r;
    r.summary_start = f.u64("summary_start");
    r.summary_offset_start = f.u64("summary_offset_start");
    r.summary_crc = f.u32("summary_crc");
    return finish(f, r);
}

Result<std::uint32_t> decode_data_end(std::span<const std::byte> content) {
    FieldReader f(content);
    auto crc = f.u32("data_section_crc");
    return finish(f, crc);
}

std::uint32_t crc32_update(std::uint32_t crc, std::span<const std::byte> bytes) {
    // zlib takes uInt lengths: feed at most 1 GiB at a time.
    uLong c = crc;
    auto p = reinterpret_cast<const Bytef*>(bytes.data());
    std::size_t left = bytes.size();
    while (left > 0) {
        auto n = static_cast<uInt>(std::min<std::size_t>(left, 1u << 30));
        c = ::crc32(c, p, n);
        p += n;
        left -= n;
    }
    return static_cast<std::uint32_t>(c);
}

Unexpected record_error(std::uint8_t opcode, std::uint64_t offset, const RRError& reason) {
    return record_error(opcode, offset, reason.type, reason.message);
}

Unexpected record_error(std::uint8_t opcode, std::uint64_t offset, MessageErrorType type, const std::string& reason) {
    return fail(type, "mcap: " + opcode_name(opcode) + " at offset " + std::to_string(offset) + ": " + reason);
}

}  // namespace rr::mcap::detail
