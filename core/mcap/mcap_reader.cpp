#include "core/mcap/mcap_reader.hpp"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <utility>
#include <vector>

#include "base/codec/endian.hpp"
#include "core/mcap/mcap_compression.hpp"
#include "core/mcap/mcap_record_codec.hpp"

namespace rr::mcap {

using detail::Bytes;
using detail::kRecordPrefixBytes;
using detail::record_error;

// Named, not anonymous: MessageIterator::State holds a LinearScanner and a RecordWalker.
namespace reader_detail {

constexpr auto kCorrupt = MessageErrorType::DataSerializationError;

std::uint8_t op(Opcode o) { return static_cast<std::uint8_t>(o); }

// The file must hold the bytes before memory is allocated for them.
Result<Bytes> read_bytes(Source& source, std::uint64_t offset, std::uint64_t n) {
    const std::uint64_t size = source.size();
    if (offset > size || n > size - offset)
        return fail(MessageErrorType::IOError, "mcap: " + std::to_string(n) + " bytes at offset " + std::to_string(offset) +
                                                   " are past the end of the file (" + std::to_string(size) + " bytes)");
    Bytes out(static_cast<std::size_t>(n));
    if (auto r = source.read_at(offset, out); !r) return r.take_error();
    return out;
}

// What the reader holds, counted against ReaderLimits::max_memory_bytes (mcap_reader.hpp).
struct MemoryBudget {
    std::uint64_t limit = 0;
    std::uint64_t held = 0;
};

// Bytes counted in a MemoryBudget for as long as this lives (or until sub/release).
class Charge {
public:
    Charge() = default;
    explicit Charge(MemoryBudget* budget) : budget_(budget) {}
    Charge(Charge&& o) noexcept : budget_(std::exchange(o.budget_, nullptr)), bytes_(std::exchange(o.bytes_, 0)) {}
    Charge& operator=(Charge&& o) noexcept {
        if (this != &o) {
            release();
            budget_ = std::exchange(o.budget_, nullptr);
            bytes_ = std::exchange(o.bytes_, 0);
        }
        return *this;
    }
    ~Charge() { release(); }

    // Counts `n` more bytes, or fails (counting nothing) when that would pass the limit.
    Result<void> add(std::uint64_t n, std::uint8_t opcode, std::uint64_t offset, std::string_view what) {
        if (n > budget_->limit || budget_->held > budget_->limit - n)
            return detail::record_error(opcode, offset, MessageErrorType::BufferLimitViolation,
                                        std::string(what) + " (" + std::to_string(n) +
                                            " bytes) would take the reader over its memory limit of " +
                                            std::to_string(budget_->limit) + " bytes (" + std::to_string(budget_->held) +
                                            " held)");
        budget_->held += n;
        bytes_ += n;
        return {};
    }
    void sub(std::uint64_t n) {
        if (!budget_) return;
        n = std::min(n, bytes_);
        budget_->held -= n;
        bytes_ -= n;
    }
    void release() {
        if (budget_) budget_->held -= bytes_;
        bytes_ = 0;
    }

private:
    MemoryBudget* budget_ = nullptr;
    std::uint64_t bytes_ = 0;
};

struct RawRecord {
    std::uint8_t opcode = 0;
    std::uint64_t offset = 0;  // file offset of the opcode
    Bytes content;
    Charge charge;  // for content
};

// Reads the data section record by record, from `pos` to Data End or the end of the file. A record
// cut off by the end of the file ends the read and is reported in truncated, not as an error.
class LinearScanner {
public:
    LinearScanner(Source& source, const ReaderLimits& limits, MemoryBudget& budget, std::uint64_t pos)
        : source_(source), limits_(limits), budget_(budget), pos_(pos) {}

    Result<std::optional<RawRecord>> next() {
        if (done_) return std::optional<RawRecord>{};
        const std::uint64_t size = source_.size();
        if (pos_ == size) return stop("file ends at offset " + std::to_string(pos_) + " without a DataEnd record");
        if (size - pos_ < kRecordPrefixBytes)
            return stop("file ends inside a record prefix at offset " + std::to_string(pos_));
        std::byte prefix[kRecordPrefixBytes];
        if (auto r = source_.read_at(pos_, prefix); !r) return r.take_error();
        const auto opcode = static_cast<std::uint8_t>(prefix[0]);
        const auto length = load_le<std::uint64_t>(prefix + 1);
        if (opcode == 0) return record_error(opcode, pos_, kCorrupt, "opcode 0 is not a record");
        if (length > size - pos_ - kRecordPrefixBytes)
            return stop("file ends inside " + opcode_name(opcode) + " at offset " + std::to_string(pos_) +
                        " (content length " + std::to_string(length) + ", " +
                        std::to_string(size - pos_ - kRecordPrefixBytes) + " bytes left)");
        RawRecord rec{opcode, pos_, {}, Charge(&budget_)};
        if (opcode == op(Opcode::DataEnd) || opcode == op(Opcode::Footer)) done_ = true;
        if (!wanted_content(opcode)) {  // attachments, metadata, indexes, private records: skipped unread
            pos_ += kRecordPrefixBytes + length;
            return std::optional<RawRecord>(std::move(rec));
        }
        if (length > limits_.max_record_bytes)
            return record_error(opcode, pos_, MessageErrorType::BufferLimitViolation,
                                "content length " + std::to_string(length) + " over the limit of " +
                                    std::to_string(limits_.max_record_bytes) + " bytes");
        if (auto r = rec.charge.add(length, opcode, pos_, "its content"); !r) return r.take_error();
        auto content = read_bytes(source_, pos_ + kRecordPrefixBytes, length);
        if (!content) return content.take_error();
        rec.content = std::move(*content);
        pos_ += kRecordPrefixBytes + length;
        return std::optional<RawRecord>(std::move(rec));
    }

    const std::optional<std::string>& truncated() const { return truncated_; }

private:
    // Records whose content a linear read uses; the others are stepped over (a linear read only counts
    // Attachment and Metadata records).
    static bool wanted_content(std::uint8_t opcode) {
        return opcode == op(Opcode::Schema) || opcode == op(Opcode::Channel) || opcode == op(Opcode::Message) ||
               opcode == op(Opcode::Chunk);
    }

    Result<std::optional<RawRecord>> stop(std::string why) {
        done_ = true;
        truncated_ = std::move(why);
        return std::optional<RawRecord>{};
    }

    Source& source_;
    const ReaderLimits& limits_;
    MemoryBudget& budget_;
    std::uint64_t pos_;
    bool done_ = false;
    std::optional<std::string> truncated_;
};

// A chunk's decompressed records and their place in the memory budget.
struct LoadedChunk {
    Bytes records;
    Charge charge;
};

// Decompresses and CRC-checks a Chunk record's records; their announced size is counted in `budget`
// before decompressing.
Result<LoadedChunk> load_chunk(std::span<const std::byte> content, std::uint64_t offset, const ReaderLimits& limits,
                               MemoryBudget& budget, detail::ChunkRecord* fields = nullptr) {
    auto chunk = detail::decode_chunk(content);
    if (!chunk) return record_error(op(Opcode::Chunk), offset, chunk.error());
    if (chunk->uncompressed_size > limits.max_chunk_uncompressed_bytes)
        return record_error(op(Opcode::Chunk), offset, MessageErrorType::BufferLimitViolation,
                            "uncompressed_size " + std::to_string(chunk->uncompressed_size) + " over the limit of " +
                                std::to_string(limits.max_chunk_uncompressed_bytes) + " bytes");
    LoadedChunk loaded{{}, Charge(&budget)};
    if (auto r = loaded.charge.add(chunk->uncompressed_size, op(Opcode::Chunk), offset, "its uncompressed records"); !r)
        return r.take_error();
    auto records = detail::decompress_chunk(chunk->compression, chunk->records, chunk->uncompressed_size);
    if (!records) return record_error(op(Opcode::Chunk), offset, records.error());
    if (chunk->uncompressed_crc != 0) {
        auto crc = detail::crc32_update(0, *records);
        if (crc != chunk->uncompressed_crc) {
            char buf[96];
            std::snprintf(buf, sizeof buf, "uncompressed_crc mismatch (file 0x%08X, computed 0x%08X)",
                          static_cast<unsigned>(chunk->uncompressed_crc), static_cast<unsigned>(crc));
            return record_error(op(Opcode::Chunk), offset, kCorrupt, buf);
        }
    }
    if (fields) *fields = *chunk;  // its records view points into `content`
    loaded.records = std::move(*records);
    return loaded;
}

// Walks the records inside a decompressed chunk (or a summary section). A record that does not fit is
// an error: the enclosing bytes are complete.
class RecordWalker {
public:
    RecordWalker(std::span<const std::byte> bytes, std::uint64_t base_offset, std::string where)
        : bytes_(bytes), base_(base_offset), where_(std::move(where)) {}

    struct Item {
        std::uint8_t opcode;
        std::uint64_t offset;  // base_offset + position
        std::span<const std::byte> content;
    };

    Result<std::optional<Item>> next() {
        if (pos_ == bytes_.size()) return std::optional<Item>{};
        const std::uint64_t at = base_ + pos_;
        if (bytes_.size() - pos_ < kRecordPrefixBytes)
            return fail(kCorrupt, "mcap: record at offset " + std::to_string(at) + where_ + ": " +
                                      std::to_string(bytes_.size() - pos_) + " stray bytes, not a record");
        const auto opcode = static_cast<std::uint8_t>(bytes_[pos_]);
        const auto length = load_le<std::uint64_t>(bytes_.data() + pos_ + 1);
        if (opcode == 0) return record_error(opcode, at, kCorrupt, std::string("opcode 0 is not a record") + where_);
        if (length > bytes_.size() - pos_ - kRecordPrefixBytes)
            return record_error(opcode, at, kCorrupt,
                                "content length " + std::to_string(length) + " exceeds the " +
                                    std::to_string(bytes_.size() - pos_ - kRecordPrefixBytes) + " bytes left" + where_);
        Item item{opcode, at, bytes_.subspan(pos_ + kRecordPrefixBytes, static_cast<std::size_t>(length))};
        pos_ += kRecordPrefixBytes + static_cast<std::size_t>(length);
        return std::optional<Item>(item);
    }

private:
    std::span<const std::byte> bytes_;
    std::uint64_t base_;
    std::string where_;
    std::size_t pos_ = 0;
};

std::string in_chunk(std::uint64_t chunk_offset) {
    return " (inside the Chunk at offset " + std::to_string(chunk_offset) + ")";
}

bool wanted(const MessageQuery& q, std::uint16_t channel, std::uint64_t log_time) {
    return log_time >= q.start_time && (!q.end_time || log_time < *q.end_time) &&
           (!q.channels || q.channels->count(channel));
}

}  // namespace reader_detail
using namespace reader_detail;

struct McapReader::State {
    Source* source = nullptr;
    ReaderLimits limits;
    Header header;
    Summary summary;
    bool indexed = false;
    std::optional<std::string> truncated;
    std::uint64_t data_start = 0;
    MemoryBudget budget;
    Charge summary_charge{&budget};  // the decoded summary's records

    Result<void> read_footer_and_summary();
    // Refuses Chunk Index records that name one chunk twice or overlapping chunks, and chunks that could
    // never be read within the memory limit. `record_offsets`: each ChunkIndex record's file offset.
    Result<void> check_chunk_indexes(const std::vector<ChunkIndex>& indexes, const std::vector<std::uint64_t>& record_offsets);
    Result<void> scan_linear();
    // Adds a Schema/Channel seen in the data; returns an error for a message on an unknown channel.
    Result<void> note_record(std::uint8_t opcode, std::uint64_t offset, std::span<const std::byte> content,
                             std::uint64_t chunk_offset);
};

Result<void> McapReader::State::read_footer_and_summary() {
    const std::uint64_t size = source->size();
    constexpr std::uint64_t kTail = detail::kFooterRecordBytes + kMagic.size();
    if (size < data_start + kTail) return {};
    auto tail = read_bytes(*source, size - kTail, kTail);
    if (!tail) return tail.take_error();
    if (std::memcmp(tail->data() + detail::kFooterRecordBytes, kMagic.data(), kMagic.size()) != 0) return {};
    const std::uint64_t footer_at = size - kTail;
    if (static_cast<std::uint8_t>((*tail)[0]) != op(Opcode::Footer) || load_le<std::uint64_t>(tail->data() + 1) != 20)
        return {};  // not a footer: a linear read decides what the file holds
    auto footer = detail::decode_footer(std::span(*tail).subspan(kRecordPrefixBytes, 20));
    if (!footer) return record_error(op(Opcode::Footer), footer_at, footer.error());
    if (footer->summary_start == 0) return {};
    const auto& f = *footer;
    if (f.summary_start < data_start || f.summary_start > footer_at ||
        (f.summary_offset_start != 0 && (f.summary_offset_start < f.summary_start || f.summary_offset_start > footer_at)))
        return record_error(op(Opcode::Footer), footer_at, kCorrupt,
                            "summary_start " + std::to_string(f.summary_start) + " / summary_offset_start " +
                                std::to_string(f.summary_offset_start) + " outside the file's summary area");
    if (footer_at - f.summary_start > limits.max_summary_bytes)
        return record_error(op(Opcode::Footer), footer_at, MessageErrorType::BufferLimitViolation,
                            "summary of " + std::to_string(footer_at - f.summary_start) + " bytes over the limit of " +
                                std::to_string(limits.max_summary_bytes));
    // The CRC covers the summary, the summary offsets and the footer up to summary_crc.
    constexpr std::uint64_t kFooterCovered = kRecordPrefixBytes + 16;
    Charge covered_charge(&budget);
    if (auto r = covered_charge.add(footer_at - f.summary_start + kFooterCovered, op(Opcode::Footer), footer_at, "the summary section");
        !r)
        return r;
    auto covered = read_bytes(*source, f.summary_start, footer_at - f.summary_start + kFooterCovered);
    if (!covered) return covered.take_error();
    if (f.summary_crc != 0) {
        auto crc = detail::crc32_update(0, *covered);
        if (crc != f.summary_crc) {
            char buf[96];
            std::snprintf(buf, sizeof buf, "summary_crc mismatch (file 0x%08X, computed 0x%08X)",
                          static_cast<unsigned>(f.summary_crc), static_cast<unsigned>(crc));
            return record_error(op(Opcode::Footer), footer_at, kCorrupt, buf);
        }
    }
    const std::uint64_t summary_end = f.summary_offset_start ? f.summary_offset_start : footer_at;
    const auto summary_bytes = std::span<const std::byte>(*covered).first(
        static_cast<std::size_t>(summary_end - f.summary_start));
    RecordWalker walk(summary_bytes, f.summary_start, " (in the summary section)");
    Summary s;
    s.from_summary_section = true;
    bool have_statistics = false;
    std::vector<std::uint64_t> chunk_index_offsets;
    summary_charge.release();
    for (;;) {
        auto item = walk.next();
        if (!item) return item.take_error();
        if (!*item) break;
        const auto& [opcode, at, content] = **item;
        if (opcode == op(Opcode::Schema)) {
            auto x = detail::decode_schema(content);
            if (!x) return record_error(opcode, at, x.error());
            if (x->id == 0) continue;
            if (auto r = summary_charge.add(memory_of(*x), opcode, at, "the decoded summary"); !r) return r;
            if (auto old = s.schemas.find(x->id); old != s.schemas.end()) summary_charge.sub(memory_of(old->second));
            s.schemas[x->id] = std::move(*x);
        } else if (opcode == op(Opcode::Channel)) {
            auto x = detail::decode_channel(content);
            if (!x) return record_error(opcode, at, x.error());
            if (auto r = summary_charge.add(memory_of(*x), opcode, at, "the decoded summary"); !r) return r;
            if (auto old = s.channels.find(x->id); old != s.channels.end()) summary_charge.sub(memory_of(old->second));
            s.channels[x->id] = std::move(*x);
        } else if (opcode == op(Opcode::ChunkIndex)) {
            auto x = detail::decode_chunk_index(content);
            if (!x) return record_error(opcode, at, x.error());
            if (x->chunk_start_offset < data_start || x->chunk_length < kRecordPrefixBytes ||
                x->chunk_start_offset > size || x->chunk_length > size - x->chunk_start_offset)
                return record_error(opcode, at, kCorrupt,
                                    "chunk at offset " + std::to_string(x->chunk_start_offset) + " length " +
                                        std::to_string(x->chunk_length) + " is outside the file");
            if (auto r = summary_charge.add(memory_of(*x), opcode, at, "the decoded summary"); !r) return r;
            s.chunk_indexes.push_back(std::move(*x));
            chunk_index_offsets.push_back(at);
        } else if (opcode == op(Opcode::Statistics)) {
            auto x = detail::decode_statistics(content);
            if (!x) return record_error(opcode, at, x.error());
            s.statistics = std::move(*x);
            have_statistics = true;
        }
    }
    if (!have_statistics) {
        s.statistics.schema_count = static_cast<std::uint16_t>(s.schemas.size());
        s.statistics.channel_count = static_cast<std::uint32_t>(s.channels.size());
        s.statistics.chunk_count = static_cast<std::uint32_t>(s.chunk_indexes.size());
    }
    if (s.chunk_indexes.empty()) {  // no index: read linearly
        summary_charge.release();
        return {};
    }
    if (auto r = check_chunk_indexes(s.chunk_indexes, chunk_index_offsets); !r) return r;
    summary = std::move(s);
    indexed = true;
    return {};
}

Result<void> McapReader::State::check_chunk_indexes(const std::vector<ChunkIndex>& indexes,
                                                    const std::vector<std::uint64_t>& record_offsets) {
    std::vector<std::size_t> order(indexes.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        return indexes[a].chunk_start_offset < indexes[b].chunk_start_offset;
    });
    // Each chunk indexed once, chunks apart: checked first, it is the more telling error.
    for (std::size_t k = 1; k < order.size(); ++k) {
        const auto& ci = indexes[order[k]];
        const auto at = record_offsets[order[k]];
        const auto& prev = indexes[order[k - 1]];
        if (ci.chunk_start_offset == prev.chunk_start_offset)
            return record_error(op(Opcode::ChunkIndex), at, kCorrupt,
                                "a second index of the chunk at offset " + std::to_string(ci.chunk_start_offset) +
                                    " (the ChunkIndex at offset " + std::to_string(record_offsets[order[k - 1]]) +
                                    " names it too; each chunk is indexed once)");
        if (ci.chunk_start_offset < prev.chunk_start_offset + prev.chunk_length)
            return record_error(op(Opcode::ChunkIndex), at, kCorrupt,
                                "the chunk at offset " + std::to_string(ci.chunk_start_offset) +
                                    " begins inside the chunk at offset " + std::to_string(prev.chunk_start_offset) +
                                    " (length " + std::to_string(prev.chunk_length) + ")");
    }
    for (std::size_t k = 0; k < order.size(); ++k) {
        const auto& ci = indexes[order[k]];
        const auto at = record_offsets[order[k]];
        // The chunk's compressed content and its records decompressed are held at once while it is read.
        const std::uint64_t need = ci.chunk_length + ci.uncompressed_size;
        if (ci.uncompressed_size > budget.limit || need > budget.limit || budget.held > budget.limit - need)
            return record_error(op(Opcode::ChunkIndex), at, MessageErrorType::BufferLimitViolation,
                                "the chunk at offset " + std::to_string(ci.chunk_start_offset) + " (" +
                                    std::to_string(ci.uncompressed_size) +
                                    " bytes uncompressed) can never be read within the reader's memory limit of " +
                                    std::to_string(budget.limit) + " bytes (" + std::to_string(budget.held) +
                                    " held by the summary)");
    }
    return {};
}

Result<void> McapReader::State::note_record(std::uint8_t opcode, std::uint64_t offset,
                                            std::span<const std::byte> content, std::uint64_t chunk_offset) {
    auto where = [&] { return chunk_offset ? in_chunk(chunk_offset) : std::string(); };
    auto& st = summary.statistics;
    if (opcode == op(Opcode::Schema)) {
        auto x = detail::decode_schema(content);
        if (!x) return record_error(opcode, offset, kCorrupt, x.error().message + where());
        if (x->id == 0) return {};
        if (auto r = summary_charge.add(memory_of(*x), opcode, offset, "the summary gathered so far"); !r) return r;
        if (auto old = summary.schemas.find(x->id); old != summary.schemas.end()) summary_charge.sub(memory_of(old->second));
        summary.schemas[x->id] = std::move(*x);
    } else if (opcode == op(Opcode::Channel)) {
        auto x = detail::decode_channel(content);
        if (!x) return record_error(opcode, offset, kCorrupt, x.error().message + where());
        if (auto r = summary_charge.add(memory_of(*x), opcode, offset, "the summary gathered so far"); !r) return r;
        if (auto old = summary.channels.find(x->id); old != summary.channels.end()) summary_charge.sub(memory_of(old->second));
        summary.channels[x->id] = std::move(*x);
    } else if (opcode == op(Opcode::Message)) {
        // Only the fixed fields: the data is not needed to count.
        if (content.size() < 22) return record_error(opcode, offset, kCorrupt, "shorter than its 22 fixed bytes" + where());
        auto channel = load_le<std::uint16_t>(content.data());
        auto log_time = load_le<std::uint64_t>(content.data() + 6);
        if (!summary.channels.count(channel))
            return record_error(opcode, offset, kCorrupt,
                                "channel " + std::to_string(channel) + " is not defined before it" + where());
        if (st.message_count == 0) st.message_start_time = st.message_end_time = log_time;
        st.message_start_time = std::min(st.message_start_time, log_time);
        st.message_end_time = std::max(st.message_end_time, log_time);
        ++st.message_count;
        ++st.channel_message_counts[channel];
    } else if (opcode == op(Opcode::Attachment)) {
        ++st.attachment_count;
    } else if (opcode == op(Opcode::Metadata)) {
        ++st.metadata_count;
    }
    return {};
}

Result<void> McapReader::State::scan_linear() {
    summary = Summary{};
    summary_charge.release();
    LinearScanner scan(*source, limits, budget, data_start);
    for (;;) {
        auto rec = scan.next();
        if (!rec) return rec.take_error();
        if (!*rec) break;
        const RawRecord& r = **rec;
        if (r.opcode != op(Opcode::Chunk)) {
            if (auto x = note_record(r.opcode, r.offset, r.content, 0); !x) return x;
            continue;
        }
        detail::ChunkRecord fields;
        auto records = load_chunk(r.content, r.offset, limits, budget, &fields);
        if (!records) return records.take_error();
        RecordWalker walk(records->records, 0, in_chunk(r.offset));
        for (;;) {
            auto item = walk.next();
            if (!item) return item.take_error();
            if (!*item) break;
            if (auto x = note_record((*item)->opcode, (*item)->offset, (*item)->content, r.offset); !x) return x;
        }
        ChunkIndex ci;
        ci.message_start_time = fields.message_start_time;
        ci.message_end_time = fields.message_end_time;
        ci.chunk_start_offset = r.offset;
        ci.chunk_length = kRecordPrefixBytes + r.content.size();
        ci.compression = fields.compression;
        ci.compressed_size = fields.records.size();
        ci.uncompressed_size = fields.uncompressed_size;
        if (auto x = summary_charge.add(memory_of(ci), op(Opcode::Chunk), r.offset, "the summary gathered so far"); !x) return x;
        summary.chunk_indexes.push_back(std::move(ci));
        ++summary.statistics.chunk_count;
    }
    summary.statistics.schema_count = static_cast<std::uint16_t>(summary.schemas.size());
    summary.statistics.channel_count = static_cast<std::uint32_t>(summary.channels.size());
    truncated = scan.truncated();
    return {};
}

Result<McapReader> McapReader::open(Source& source, ReaderLimits limits) {
    auto s = std::make_unique<State>();
    s->source = &source;
    s->limits = limits;
    s->budget.limit = limits.max_memory_bytes;
    const std::uint64_t size = source.size();
    if (size < kMagic.size())
        return fail(kCorrupt, "mcap: not an MCAP file: " + std::to_string(size) + " bytes, shorter than the magic");
    auto magic = read_bytes(source, 0, kMagic.size());
    if (!magic) return magic.take_error();
    if (std::memcmp(magic->data(), kMagic.data(), kMagic.size()) != 0)
        return fail(kCorrupt, "mcap: not an MCAP file: the first 8 bytes are not the MCAP magic");
    const std::uint64_t at = kMagic.size();
    if (size - at < kRecordPrefixBytes)
        return fail(kCorrupt, "mcap: file ends before the Header record (" + std::to_string(size) + " bytes)");
    auto prefix = read_bytes(source, at, kRecordPrefixBytes);
    if (!prefix) return prefix.take_error();
    const auto opcode = static_cast<std::uint8_t>((*prefix)[0]);
    const auto length = load_le<std::uint64_t>(prefix->data() + 1);
    if (opcode != op(Opcode::Header))
        return record_error(opcode, at, kCorrupt, "the first record must be a Header");
    if (length > size - at - kRecordPrefixBytes)
        return record_error(opcode, at, kCorrupt, "file ends inside the Header record");
    if (length > limits.max_record_bytes)
        return record_error(opcode, at, MessageErrorType::BufferLimitViolation, "Header over the record limit");
    Charge header_charge(&s->budget);
    if (auto r = header_charge.add(length, opcode, at, "its content"); !r) return r.take_error();
    auto content = read_bytes(source, at + kRecordPrefixBytes, length);
    if (!content) return content.take_error();
    auto header = detail::decode_header(*content);
    if (!header) return record_error(opcode, at, header.error());
    s->header = std::move(*header);
    s->data_start = at + kRecordPrefixBytes + length;

    if (auto r = s->read_footer_and_summary(); !r) return r.take_error();
    if (!s->indexed) {
        if (auto r = s->scan_linear(); !r) return r.take_error();
    }
    return McapReader(std::move(s));
}

McapReader::McapReader(std::unique_ptr<State> s) : s_(std::move(s)) {}
McapReader::McapReader(McapReader&&) noexcept = default;
McapReader& McapReader::operator=(McapReader&&) noexcept = default;
McapReader::~McapReader() = default;

const Header& McapReader::header() const noexcept { return s_->header; }
const Summary& McapReader::summary() const noexcept { return s_->summary; }
bool McapReader::indexed() const noexcept { return s_->indexed; }
const std::optional<std::string>& McapReader::truncated() const noexcept { return s_->truncated; }
std::uint64_t McapReader::memory_bytes() const noexcept { return s_->budget.held; }

// ---------------------------------------------------------------------------------------------------

struct MessageIterator::State {
    McapReader::State* reader = nullptr;
    MessageQuery query;
    std::optional<RRError> error;
    bool done = false;

    // Linear: the scanner, and the chunk being walked.
    std::optional<LinearScanner> scanner;
    LoadedChunk chunk;
    std::optional<RecordWalker> walker;
    std::uint64_t chunk_offset = 0;

    // Indexed: chunks still to load (by start time), and the loaded messages as a min-heap.
    struct Pending {
        std::uint64_t log_time;
        std::uint64_t chunk_offset;   // ties in log_time keep file order
        std::uint64_t record_offset;
        Message message;
    };
    std::vector<const ChunkIndex*> chunks;
    std::size_t next_chunk = 0;
    std::vector<Pending> heap;
    Charge heap_charge;  // the messages in `heap`
    static std::uint64_t weight(const Message& m) { return sizeof(Pending) + m.data.size(); }

    static bool later(const Pending& a, const Pending& b) {
        if (a.log_time != b.log_time) return a.log_time > b.log_time;
        if (a.chunk_offset != b.chunk_offset) return a.chunk_offset > b.chunk_offset;
        return a.record_offset > b.record_offset;
    }

    Result<std::optional<Message>> fail_with(Unexpected u) {
        error = *u.error;
        return u;
    }

    // A Message record's content → Message if the query wants it.
    Result<std::optional<Message>> message_from(std::span<const std::byte> content, std::uint64_t offset,
                                                std::uint64_t in_chunk_at) {
        auto m = detail::decode_message(content);
        if (!m) return record_error(op(Opcode::Message), offset, kCorrupt,
                                    m.error().message + (in_chunk_at ? in_chunk(in_chunk_at) : std::string()));
        if (!reader->summary.channels.count(m->channel_id))
            return record_error(op(Opcode::Message), offset, kCorrupt,
                                "channel " + std::to_string(m->channel_id) + " is not defined" +
                                    (in_chunk_at ? in_chunk(in_chunk_at) : std::string()));
        if (!wanted(query, m->channel_id, m->log_time)) return std::optional<Message>{};
        return std::optional<Message>(std::move(*m));
    }

    bool chunk_wanted(const ChunkIndex& ci) const {
        if (ci.message_end_time < query.start_time || (query.end_time && ci.message_start_time >= *query.end_time))
            return false;
        if (query.channels && !ci.message_index_offsets.empty()) {
            bool any = false;
            for (auto c : *query.channels) any = any || ci.message_index_offsets.count(c);
            return any;
        }
        return true;
    }

    Result<std::optional<Message>> next_linear();
    Result<std::optional<Message>> next_indexed();
    Result<void> load_indexed_chunk(const ChunkIndex& ci);
};

Result<std::optional<Message>> MessageIterator::State::next_linear() {
    for (;;) {
        if (walker) {
            auto item = walker->next();
            if (!item) return fail_with(item.take_error());
            if (!*item) {
                walker.reset();
                chunk = LoadedChunk{};
                continue;
            }
            if ((*item)->opcode != op(Opcode::Message)) continue;
            auto m = message_from((*item)->content, (*item)->offset, chunk_offset);
            if (!m) return fail_with(m.take_error());
            if (*m) return m;
            continue;
        }
        auto rec = scanner->next();
        if (!rec) return fail_with(rec.take_error());
        if (!*rec) {
            done = true;
            return std::optional<Message>{};
        }
        RawRecord& r = **rec;
        if (r.opcode == op(Opcode::Message)) {
            auto m = message_from(r.content, r.offset, 0);
            if (!m) return fail_with(m.take_error());
            if (*m) return m;
        } else if (r.opcode == op(Opcode::Chunk)) {
            auto records = load_chunk(r.content, r.offset, reader->limits, reader->budget);
            if (!records) return fail_with(records.take_error());
            chunk = std::move(*records);
            chunk_offset = r.offset;
            walker.emplace(chunk.records, 0, in_chunk(r.offset));
        }
    }
}

Result<void> MessageIterator::State::load_indexed_chunk(const ChunkIndex& ci) {
    const auto& limits = reader->limits;
    const auto at = ci.chunk_start_offset;
    auto prefix = read_bytes(*reader->source, at, kRecordPrefixBytes);
    if (!prefix) return prefix.take_error();
    const auto opcode = static_cast<std::uint8_t>((*prefix)[0]);
    const auto length = load_le<std::uint64_t>(prefix->data() + 1);
    if (opcode != op(Opcode::Chunk))
        return record_error(op(Opcode::ChunkIndex), at, kCorrupt, "points at a " + opcode_name(opcode) + ", not a Chunk");
    if (length > ci.chunk_length - kRecordPrefixBytes)
        return record_error(opcode, at, kCorrupt, "content length " + std::to_string(length) +
                                                      " exceeds chunk_length in its ChunkIndex");
    if (length > limits.max_record_bytes)
        return record_error(opcode, at, MessageErrorType::BufferLimitViolation,
                            "content length " + std::to_string(length) + " over the record limit");
    Charge content_charge(&reader->budget);
    if (auto r = content_charge.add(length, opcode, at, "its content"); !r) return r;
    auto content = read_bytes(*reader->source, at + kRecordPrefixBytes, length);
    if (!content) return content.take_error();
    auto records = load_chunk(*content, at, limits, reader->budget);
    if (!records) return records.take_error();
    Bytes().swap(*content);  // the compressed bytes are done with
    content_charge.release();
    RecordWalker walk(records->records, 0, in_chunk(at));
    for (;;) {
        auto item = walk.next();
        if (!item) return item.take_error();
        if (!*item) break;
        if ((*item)->opcode != op(Opcode::Message)) continue;
        // The merge by log_time trusts the ChunkIndex time ranges: a message outside its range is an error.
        if ((*item)->content.size() >= 14) {
            const auto t = load_le<std::uint64_t>((*item)->content.data() + 6);
            if (t < ci.message_start_time || t > ci.message_end_time)
                return record_error(op(Opcode::Message), (*item)->offset, kCorrupt,
                                    "log_time " + std::to_string(t) + " outside its ChunkIndex range [" +
                                        std::to_string(ci.message_start_time) + ", " +
                                        std::to_string(ci.message_end_time) + "]" + in_chunk(at));
        }
        auto m = message_from((*item)->content, (*item)->offset, at);
        if (!m) return m.take_error();
        if (!*m) continue;
        const auto t = (**m).log_time;
        if (auto r = heap_charge.add(weight(**m), op(Opcode::Message), (*item)->offset, "the messages waiting to be read");
            !r)
            return r;
        heap.push_back(Pending{t, at, (*item)->offset, std::move(**m)});
        std::push_heap(heap.begin(), heap.end(), later);
    }
    return {};
}

Result<std::optional<Message>> MessageIterator::State::next_indexed() {
    while (next_chunk < chunks.size() &&
           (heap.empty() || chunks[next_chunk]->message_start_time <= heap.front().log_time)) {
        if (auto r = load_indexed_chunk(*chunks[next_chunk]); !r) return fail_with(r.take_error());
        ++next_chunk;
    }
    if (heap.empty()) {
        done = true;
        return std::optional<Message>{};
    }
    std::pop_heap(heap.begin(), heap.end(), later);
    Message m = std::move(heap.back().message);
    heap.pop_back();
    heap_charge.sub(weight(m));
    return std::optional<Message>(std::move(m));
}

MessageIterator::MessageIterator(std::unique_ptr<State> s) : s_(std::move(s)) {}
MessageIterator::MessageIterator(MessageIterator&&) noexcept = default;
MessageIterator& MessageIterator::operator=(MessageIterator&&) noexcept = default;
MessageIterator::~MessageIterator() = default;

Result<std::optional<Message>> MessageIterator::next() {
    if (s_->error) return fail(*s_->error);
    if (s_->done) return std::optional<Message>{};
    return s_->reader->indexed ? s_->next_indexed() : s_->next_linear();
}

MessageIterator McapReader::messages(MessageQuery query) {
    auto it = std::make_unique<MessageIterator::State>();
    it->reader = s_.get();
    it->query = std::move(query);
    it->heap_charge = Charge(&s_->budget);
    if (s_->indexed) {
        for (const auto& ci : s_->summary.chunk_indexes)
            if (it->chunk_wanted(ci)) it->chunks.push_back(&ci);
        std::stable_sort(it->chunks.begin(), it->chunks.end(), [](const ChunkIndex* a, const ChunkIndex* b) {
            return a->message_start_time < b->message_start_time;
        });
    } else {
        it->scanner.emplace(*s_->source, s_->limits, s_->budget, s_->data_start);
    }
    return MessageIterator(std::move(it));
}

}  // namespace rr::mcap
