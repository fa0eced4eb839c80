// Encoding and decoding of single MCAP records (MCAP specification §Records, §Serialization). Internal
// to core/mcap: McapWriter and McapReader build on it; the fuzz target reaches it through McapReader.
//
// Encoders append a whole record (opcode, uint64 content length, content) to a byte vector.
// Decoders take a record's content (after the 9-byte record prefix) and read it with a bounded
// cursor: every length is checked against the bytes left, nothing is allocated before that check.
// Decoder errors are DataSerializationError with a short reason ("topic: truncated: ..."); the reader
// prefixes the record's name and offset. Fields after the known ones are ignored (§Records: records
// may be extended).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "base/error/rr_error.hpp"
#include "core/mcap/mcap_records.hpp"

namespace rr::mcap::detail {

/// Bytes of a record prefix: opcode (1) + content length (8).
inline constexpr std::size_t kRecordPrefixBytes = 9;
/// Bytes of a whole Footer record: prefix + summary_start + summary_offset_start + summary_crc.
inline constexpr std::size_t kFooterRecordBytes = kRecordPrefixBytes + 8 + 8 + 4;

using Bytes = std::vector<std::byte>;

// --- encoding -------------------------------------------------------------------------------------
void append_magic(Bytes& out);
void encode_header(Bytes& out, const Header& header);
void encode_schema(Bytes& out, const Schema& schema);
void encode_channel(Bytes& out, const Channel& channel);
void encode_message(Bytes& out, std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time,
                    std::uint64_t publish_time, std::span<const std::byte> data);
/// The Chunk record up to and including the uint64 length of `records`; the caller appends the
/// `records` bytes (records_size of them) itself, so a compressed chunk is not copied once more.
void encode_chunk_prefix(Bytes& out, std::uint64_t start_time, std::uint64_t end_time,
                         std::uint64_t uncompressed_size, std::uint32_t uncompressed_crc,
                         std::string_view compression, std::uint64_t records_size);
void encode_message_index(Bytes& out, std::uint16_t channel_id,
                          const std::vector<std::pair<std::uint64_t, std::uint64_t>>& entries);
void encode_chunk_index(Bytes& out, const ChunkIndex& index);
void encode_statistics(Bytes& out, const Statistics& statistics);
void encode_summary_offset(Bytes& out, Opcode group, std::uint64_t start, std::uint64_t length);
void encode_data_end(Bytes& out, std::uint32_t data_section_crc);
/// The Footer record without its last field (summary_crc), which covers these bytes.
void encode_footer_prefix(Bytes& out, std::uint64_t summary_start, std::uint64_t summary_offset_start);

// --- decoding -------------------------------------------------------------------------------------
/// A Chunk record's fields; `records` views into the content given to decode_chunk.
struct ChunkRecord {
    std::uint64_t message_start_time = 0;
    std::uint64_t message_end_time = 0;
    std::uint64_t uncompressed_size = 0;
    std::uint32_t uncompressed_crc = 0;
    std::string compression;
    std::span<const std::byte> records;
};

struct FooterRecord {
    std::uint64_t summary_start = 0;
    std::uint64_t summary_offset_start = 0;
    std::uint32_t summary_crc = 0;
};

Result<Header> decode_header(std::span<const std::byte> content);
Result<Schema> decode_schema(std::span<const std::byte> content);
Result<Channel> decode_channel(std::span<const std::byte> content);
Result<Message> decode_message(std::span<const std::byte> content);
Result<ChunkRecord> decode_chunk(std::span<const std::byte> content);
Result<ChunkIndex> decode_chunk_index(std::span<const std::byte> content);
Result<Statistics> decode_statistics(std::span<const std::byte> content);
Result<FooterRecord> decode_footer(std::span<const std::byte> content);
Result<std::uint32_t> decode_data_end(std::span<const std::byte> content);

/// CRC-32 (ISO-HDLC, as zlib's crc32) of `bytes`, continuing from `crc` (0 to start).
std::uint32_t crc32_update(std::uint32_t crc, std::span<const std::byte> bytes);

/// "mcap: <Record> at offset <n>: <reason>" with the reason's type kept.
Unexpected record_error(std::uint8_t opcode, std::uint64_t offset, const RRError& reason);
Unexpected record_error(std::uint8_t opcode, std::uint64_t offset, MessageErrorType type, const std::string& reason);

}  // namespace rr::mcap::detail
