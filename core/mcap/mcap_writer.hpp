// McapWriter: writes an indexed, chunked MCAP file to a Sink (MCAP specification, mcap.dev/spec).
//
// File layout written:
//   Magic, Header, then Chunks (each followed by one Message Index record per channel that has messages
//   in it), Data End, Summary (Schema, Channel, Chunk Index, Statistics records, grouped by opcode),
//   Summary Offset records, Footer, Magic.
// Schema and Channel records go into the chunk being filled when they are added (so every chunk only
// refers to schemas and channels of earlier chunks or itself), and again into the summary at close.
// Records that would make a chunk without any message (a flush() before the first message, or
// channels added after the last one) are written outside a chunk, in the data section, instead: a
// chunk without messages has no Message Index, which @mcap/core before 2.1 (Lichtblick 1.10) refuses
// to read, and its zero time range makes readers that take the chunk indexes' times start at 1970.
//
// Durability: a chunk is written to the sink (and Sink::flush called) when its uncompressed records
// reach WriterOptions::chunk_size, or on flush(). A writer killed before close() leaves a file that
// ends after its last complete chunk (plus a partial one): no Data End, summary or footer. Readers (the
// reference ones, and McapReader in its linear mode) read such a file up to the last complete chunk.
//
// Memory: the open chunk's records (about chunk_size, more only by one message larger than that),
// its compressed copy when it is written, its message indexes (16 bytes a message), and for the
// summary every schema, channel and one Chunk Index per chunk (summary_memory_bytes()).
//
// Errors: InvalidArgument (unknown schema or channel id, more than 65535 schemas or channels, a string
// or schema over 4 GiB), InvalidState (a call before open(), after close() or after an error),
// IOError (the sink's own errors, unchanged), OperationFailed (zstd failed). After any error the
// writer refuses further calls with InvalidState naming the first error; what it had written stays.
// Not thread-safe.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "base/error/rr_error.hpp"
#include "core/mcap/mcap_io.hpp"
#include "core/mcap/mcap_records.hpp"

namespace rr::mcap {

struct WriterOptions {
    /// Header `profile`. The gateway writes "" (no well-known profile fits; the channel metadata and
    /// encodings describe the content, docs/recording.md).
    std::string profile;
    /// Header `library`: writer name and version.
    std::string library = "rr-gateway mcap";
    /// Chunk compression; Zstd (libzstd) by default.
    Compression compression = Compression::Zstd;
    /// zstd level (1 fast .. 19 small); 3 is zstd's default.
    int zstd_level = 3;
    /// A chunk is closed and written once its uncompressed records reach this many bytes. Default 1 MiB.
    std::size_t chunk_size = 1024 * 1024;
};

/// A message to write. `data` is copied into the open chunk before write() returns.
struct MessageView {
    std::uint16_t channel_id = 0;
    std::uint32_t sequence = 0;
    std::uint64_t log_time = 0;      ///< ns
    std::uint64_t publish_time = 0;  ///< ns; pass log_time when unknown
    std::span<const std::byte> data;
};

class McapWriter {
public:
    /// The sink must outlive the writer. Nothing is written before open().
    explicit McapWriter(Sink& sink, WriterOptions options = {});
    ~McapWriter();
    McapWriter(const McapWriter&) = delete;
    McapWriter& operator=(const McapWriter&) = delete;

    /// Writes the magic and the Header record.
    Result<void> open();

    /// Adds a schema and returns its id (1, 2, ... in call order). `encoding` e.g. "jsonschema".
    Result<std::uint16_t> add_schema(std::string_view name, std::string_view encoding,
                                     std::span<const std::byte> data);

    /// Adds a channel and returns its id (0, 1, ... in call order). schema_id 0 means no schema;
    /// otherwise it must have come from add_schema.
    Result<std::uint16_t> add_channel(std::uint16_t schema_id, std::string_view topic,
                                      std::string_view message_encoding,
                                      const std::map<std::string, std::string>& metadata = {});

    /// Appends a message to the open chunk; writes the chunk when it is full. channel_id must have come
    /// from add_channel. Log times need not increase (readers order by log_time using the indexes).
    Result<void> write(const MessageView& message);

    /// Writes the open chunk now, if it holds any record, and flushes the sink: everything written so
    /// far survives a crash.
    Result<void> flush();

    /// Writes the open chunk, Data End, the summary, the summary offsets, the footer and the closing
    /// magic, then flushes the sink. Later calls fail with InvalidState. The destructor does NOT close:
    /// an unclosed file is what a crash leaves.
    Result<void> close();

    /// Bytes written to the sink so far.
    std::uint64_t bytes_written() const noexcept;
    /// About how much memory the writer keeps for the summary it writes at close (every schema, channel
    /// and Chunk Index, memory_of() in mcap_records.hpp): it grows by one Chunk Index per chunk for the
    /// life of the file, so a long recording rotates its file when this passes a bound
    /// (docs/recording.md "Rotation and budget").
    std::size_t summary_memory_bytes() const noexcept;
    /// Counts so far (messages, chunks written, time range, per-channel counts).
    const Statistics& statistics() const noexcept;
    bool is_open() const noexcept;
    bool is_closed() const noexcept;

private:
    struct State;
    std::unique_ptr<State> s_;
};

}  // namespace rr::mcap
