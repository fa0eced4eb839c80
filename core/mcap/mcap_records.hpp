// MCAP records: the plain data the writer takes and the reader gives back (MCAP specification,
// mcap.dev/spec, major version 0; "§Records" below means that page's Records section).
//
// Byte order: every integer in an MCAP file is little-endian. Times are uint64 nanoseconds since an
// epoch the recorder chooses (the gateway uses the Unix epoch). Strings are UTF-8 as given; neither
// side validates them.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace rr::mcap {

/// The 8 bytes at the start and at the end of every MCAP file: 0x89 "MCAP" '0' '\r' '\n' (§Magic).
inline constexpr std::array<std::uint8_t, 8> kMagic = {0x89, 'M', 'C', 'A', 'P', 0x30, '\r', '\n'};

/// Record opcodes (§Records). Every record is <opcode:uint8><content length:uint64><content>.
enum class Opcode : std::uint8_t {
    Header = 0x01,
    Footer = 0x02,
    Schema = 0x03,
    Channel = 0x04,
    Message = 0x05,
    Chunk = 0x06,
    MessageIndex = 0x07,
    ChunkIndex = 0x08,
    Attachment = 0x09,
    AttachmentIndex = 0x0A,
    Statistics = 0x0B,
    Metadata = 0x0C,
    MetadataIndex = 0x0D,
    SummaryOffset = 0x0E,
    DataEnd = 0x0F,
};

/// The spec's name of an opcode ("Chunk", "MessageIndex", ...); "private(0xNN)" or "invalid(0x00)"
/// for others. Used in error messages.
std::string opcode_name(std::uint8_t opcode);

/// Chunk compression (§Chunk `compression`): "" (None) or "zstd". lz4 is not supported: reading a
/// chunk compressed with it is an error naming the chunk.
enum class Compression { None, Zstd };

/// Header record (op 0x01): the first record of a file.
struct Header {
    std::string profile;  ///< "" for the gateway's files (see docs/recording.md)
    std::string library;  ///< free-form writer name and version
    friend bool operator==(const Header&, const Header&) = default;
};

/// Schema record (op 0x03). id 0 is invalid (it means "no schema" in a Channel).
struct Schema {
    std::uint16_t id = 0;
    std::string name;      ///< e.g. the service definition's name "experimental.reynard_the_robot"
    std::string encoding;  ///< e.g. "jsonschema", or "robotraconteur_servicedef" (docs/recording.md)
    std::vector<std::byte> data;
    friend bool operator==(const Schema&, const Schema&) = default;
};

/// Channel record (op 0x04): one stream of messages (the gateway: one member of one device).
struct Channel {
    std::uint16_t id = 0;
    std::uint16_t schema_id = 0;   ///< 0: no schema
    std::string topic;             ///< e.g. "reynard/robot_position"
    std::string message_encoding;  ///< e.g. "json" or "robotraconteur"
    std::map<std::string, std::string> metadata;
    friend bool operator==(const Channel&, const Channel&) = default;
};

/// Message record (op 0x05). The reader returns messages with their bytes copied out of the chunk.
struct Message {
    std::uint16_t channel_id = 0;
    std::uint32_t sequence = 0;      ///< per-channel counter chosen by the writer's caller
    std::uint64_t log_time = 0;      ///< ns: when it was recorded
    std::uint64_t publish_time = 0;  ///< ns: when it was sent (set to log_time when unknown)
    std::vector<std::byte> data;
    friend bool operator==(const Message&, const Message&) = default;
};

/// Chunk Index record (op 0x08): where a chunk and its message indexes are (offsets from file start).
struct ChunkIndex {
    std::uint64_t message_start_time = 0;  ///< ns, earliest log_time in the chunk (0: no messages)
    std::uint64_t message_end_time = 0;    ///< ns, latest log_time in the chunk
    std::uint64_t chunk_start_offset = 0;  ///< file offset of the Chunk record's opcode
    std::uint64_t chunk_length = 0;        ///< bytes of the whole Chunk record (opcode + length + content)
    std::map<std::uint16_t, std::uint64_t> message_index_offsets;  ///< channel id -> file offset
    std::uint64_t message_index_length = 0;  ///< bytes of the Message Index records after the chunk
    std::string compression;                 ///< "" or "zstd" (or what another writer used)
    std::uint64_t compressed_size = 0;       ///< bytes of the chunk's `records` field in the file
    std::uint64_t uncompressed_size = 0;     ///< bytes of `records` once decompressed
    friend bool operator==(const ChunkIndex&, const ChunkIndex&) = default;
};

/// Statistics record (op 0x0B).
struct Statistics {
    std::uint64_t message_count = 0;
    std::uint16_t schema_count = 0;
    std::uint32_t channel_count = 0;
    std::uint32_t attachment_count = 0;
    std::uint32_t metadata_count = 0;
    std::uint32_t chunk_count = 0;
    std::uint64_t message_start_time = 0;  ///< ns, 0 when there are no messages
    std::uint64_t message_end_time = 0;    ///< ns
    std::map<std::uint16_t, std::uint64_t> channel_message_counts;
    friend bool operator==(const Statistics&, const Statistics&) = default;
};

/// What a reader knows about a file as a whole: from its Summary section when the file has one (a
/// file closed by its writer), otherwise gathered by reading the data section up to where it ends
/// (a file whose writer was killed, or one written without a summary).
struct Summary {
    std::map<std::uint16_t, Schema> schemas;
    std::map<std::uint16_t, Channel> channels;
    std::vector<ChunkIndex> chunk_indexes;  ///< in file order
    /// From the Statistics record; when the file has none, counted while reading the data section.
    Statistics statistics;
    /// True when this came from the Summary section (the footer pointed to it), false when it was
    /// gathered by a linear read.
    bool from_summary_section = false;
};

/// About how many bytes of memory a record takes once decoded (its struct, strings, bytes and map
/// nodes): what the reader charges against ReaderLimits::max_memory_bytes and the writer reports in
/// McapWriter::summary_memory_bytes().
std::size_t memory_of(const Schema& schema) noexcept;
std::size_t memory_of(const Channel& channel) noexcept;
std::size_t memory_of(const ChunkIndex& index) noexcept;

}  // namespace rr::mcap
