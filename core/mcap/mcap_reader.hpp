// McapReader: reads MCAP files from a Source (MCAP specification, mcap.dev/spec), both the ones
// McapWriter writes and other writers' (chunked or not, zstd or uncompressed).
//
// Two ways to read, chosen by open():
//  - Indexed: the file ends with a valid footer and magic and has Chunk Index records in its summary.
//    summary() comes from the Summary section; messages() seeks to the chunks overlapping the query and
//    yields messages in log_time order (ties: file order).
//  - Linear: anything else (a file whose writer was killed, or one without a summary/indexes). open()
//    reads the data section from the start to Data End or to the end of the last complete record,
//    checking every chunk, and builds summary() from what it saw; messages() reads the file again and
//    yields messages in file order. truncated() then tells where the readable part ends.
//
// Checks: every length is checked against the bytes left in its record, the file and
// ReaderLimits before anything is allocated; chunk CRCs (when not 0) are verified; zstd output must
// have exactly the announced size, and its buffer grows with what zstd produces (a chunk's announced
// size is never allocated up front). Everything the reader holds counts against
// ReaderLimits::max_memory_bytes. An indexed file whose Chunk Index records name one chunk twice, or
// chunks whose bytes overlap, is refused at open() (each chunk would be decoded once per index). A record cut off by the end of the file ends a linear read (that is
// truncation, not an error); anything malformed inside the readable part is an error.
//
// Errors (RRError.message always names the record and its file offset, e.g.
// "mcap: Chunk at offset 1234: uncompressed_crc mismatch (file 0x..., computed 0x...)"):
//   DataSerializationError: bad magic, malformed record, CRC mismatch, bad compressed data, unknown
//     compression, a message on a channel never defined, (indexed) a message whose log_time is outside
//     its ChunkIndex's time range (the log-time merge relies on those ranges), (indexed) two Chunk
//     Index records naming one chunk or overlapping chunks;
//   BufferLimitViolation: a record or a chunk's uncompressed size over ReaderLimits, or a step that
//     would take the reader's memory over max_memory_bytes;
//   IOError: the Source's own errors, unchanged.
// Not thread-safe (an iterator counts its memory in its reader's total). The Source must outlive the
// reader, and the reader its MessageIterators (moving the reader is fine: iterators refer to state
// that stays put).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <set>
#include <string>

#include "base/error/rr_error.hpp"
#include "core/mcap/mcap_io.hpp"
#include "core/mcap/mcap_records.hpp"

namespace rr::mcap {

/// Allocation bounds for reading untrusted files. Each failure is BufferLimitViolation.
struct ReaderLimits {
    /// Largest record read into memory (a compressed chunk, a summary record, an unchunked message).
    std::uint64_t max_record_bytes = 512ull * 1024 * 1024;
    /// Largest uncompressed size a chunk may announce.
    std::uint64_t max_chunk_uncompressed_bytes = 512ull * 1024 * 1024;
    /// Largest Summary section read at open().
    std::uint64_t max_summary_bytes = 256ull * 1024 * 1024;
    /// The most memory the reader holds at once, iterators included: the decoded summary (schemas,
    /// channels, one entry per chunk), the record being read, a chunk's compressed and decompressed
    /// records, and the messages an iterator has decoded but not yet yielded. A step that would pass it
    /// fails with BufferLimitViolation instead of allocating (the gateway's replay: 256 MiB by default,
    /// recordings.replay_memory_bytes).
    std::uint64_t max_memory_bytes = 256ull * 1024 * 1024;
};

/// Which messages messages() yields.
struct MessageQuery {
    std::uint64_t start_time = 0;  ///< ns, inclusive: log_time >= start_time
    /// ns, exclusive: log_time < end_time; nullopt = no end (every time up to UINT64_MAX included).
    std::optional<std::uint64_t> end_time;
    /// Channel ids to yield; nullopt = all channels.
    std::optional<std::set<std::uint16_t>> channels;
};

class McapReader;

/// Pulls messages one at a time. Holds at most the decompressed chunks whose time ranges overlap the
/// current position (indexed) or one chunk (linear).
class MessageIterator {
public:
    MessageIterator(MessageIterator&&) noexcept;
    MessageIterator& operator=(MessageIterator&&) noexcept;
    ~MessageIterator();

    /// The next message, or nullopt at the end (for a truncated file: at the end of its last complete
    /// record). An error is final: later calls return it again.
    Result<std::optional<Message>> next();

private:
    friend class McapReader;
    struct State;
    explicit MessageIterator(std::unique_ptr<State> s);
    std::unique_ptr<State> s_;
};

class McapReader {
public:
    /// Checks the leading magic, reads the Header, then the summary (indexed) or the whole readable
    /// data section (linear), as described above. Errors: see above.
    static Result<McapReader> open(Source& source, ReaderLimits limits = {});

    McapReader(McapReader&&) noexcept;
    McapReader& operator=(McapReader&&) noexcept;
    ~McapReader();

    const Header& header() const noexcept;
    const Summary& summary() const noexcept;
    /// True when messages() can seek by time through Chunk Index records (the indexed way).
    bool indexed() const noexcept;
    /// For a linear read that ended inside a record: the file offset where the readable part ends and
    /// why ("file ends inside Chunk at offset 1234"). nullopt when the file was read to its Data End
    /// (or is indexed).
    const std::optional<std::string>& truncated() const noexcept;
    /// Bytes the reader and its iterators hold now, as counted against ReaderLimits::max_memory_bytes.
    std::uint64_t memory_bytes() const noexcept;

    /// Messages matching `query`: indexed files in log_time order, linear ones in file order.
    MessageIterator messages(MessageQuery query = {});

private:
    friend class MessageIterator;
    struct State;
    explicit McapReader(std::unique_ptr<State> s);
    std::unique_ptr<State> s_;
};

}  // namespace rr::mcap
