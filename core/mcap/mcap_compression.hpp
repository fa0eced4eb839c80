// Chunk compression for MCAP (§Chunk `compression`, registry "well-known compression formats"): none
// ("") and zstd (libzstd). Internal to core/mcap.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "base/error/rr_error.hpp"

namespace rr::mcap::detail {

/// A reusable zstd compression context (one per writer). Not thread-safe.
class ZstdCompressor {
public:
    ZstdCompressor();
    ~ZstdCompressor();
    ZstdCompressor(const ZstdCompressor&) = delete;
    ZstdCompressor& operator=(const ZstdCompressor&) = delete;

    /// Replaces `out` with one zstd frame of `in` (content size in the frame header).
    /// Errors: OperationFailed with zstd's reason.
    Result<void> compress(std::span<const std::byte> in, int level, std::vector<std::byte>& out);

private:
    void* ctx_ = nullptr;  // ZSTD_CCtx*
};

/// Decompresses a chunk's `records` into exactly `uncompressed_size` bytes. The caller has checked
/// uncompressed_size against its limit; the output buffer grows with what zstd produces (it is never
/// allocated at the announced size up front), and a zstd window over 32 MiB is refused. compression ""
/// copies. Errors (DataSerializationError): an unknown compression, bad or cut zstd data, a window
/// too large, or output of another size than announced.
Result<std::vector<std::byte>> decompress_chunk(std::string_view compression, std::span<const std::byte> records,
                                                std::uint64_t uncompressed_size);

}  // namespace rr::mcap::detail
