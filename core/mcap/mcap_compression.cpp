#include "core/mcap/mcap_compression.hpp"

#include <zstd.h>

#include <algorithm>
#include <string>

namespace rr::mcap::detail {

ZstdCompressor::ZstdCompressor() : ctx_(ZSTD_createCCtx()) {}
ZstdCompressor::~ZstdCompressor() { ZSTD_freeCCtx(static_cast<ZSTD_CCtx*>(ctx_)); }

Result<void> ZstdCompressor::compress(std::span<const std::byte> in, int level, std::vector<std::byte>& out) {
    if (!ctx_) return fail(MessageErrorType::OperationFailed, "mcap: zstd: cannot create a compression context");
    out.resize(ZSTD_compressBound(in.size()));
    std::size_t n = ZSTD_compressCCtx(static_cast<ZSTD_CCtx*>(ctx_), out.data(), out.size(), in.data(), in.size(), level);
    if (ZSTD_isError(n)) return fail(MessageErrorType::OperationFailed, std::string("mcap: zstd: ") + ZSTD_getErrorName(n));
    out.resize(n);
    return {};
}

namespace {

// The largest zstd window a chunk may ask the decoder for: 32 MiB (levels up to 19 use at most 8 MiB,
// the "ultra" levels up to 128 MiB; a frame header asking for more is refused, not allocated).
constexpr int kMaxWindowLog = 25;

struct DecompressContext {
    ZSTD_DCtx* ctx = ZSTD_createDCtx();
    ~DecompressContext() { ZSTD_freeDCtx(ctx); }
};

}  // namespace

Result<std::vector<std::byte>> decompress_chunk(std::string_view compression, std::span<const std::byte> records,
                                                std::uint64_t uncompressed_size) {
    if (compression.empty()) {
        if (records.size() != uncompressed_size)
            return fail(MessageErrorType::DataSerializationError,
                        "uncompressed records are " + std::to_string(records.size()) + " bytes, uncompressed_size says " +
                            std::to_string(uncompressed_size));
        return std::vector<std::byte>(records.begin(), records.end());
    }
    if (compression != "zstd")
        return fail(MessageErrorType::DataSerializationError,
                    "compression \"" + std::string(compression) + "\" is not supported (only \"\" and \"zstd\")");
    if (records.empty() && uncompressed_size == 0) return std::vector<std::byte>{};
    // A first frame that announces more than the whole chunk is wrong: say so before decoding.
    const unsigned long long first = ZSTD_getFrameContentSize(records.data(), records.size());
    if (first == ZSTD_CONTENTSIZE_ERROR)
        return fail(MessageErrorType::DataSerializationError, "records are not zstd data");
    if (first != ZSTD_CONTENTSIZE_UNKNOWN && first > uncompressed_size)
        return fail(MessageErrorType::DataSerializationError,
                    "zstd frame announces " + std::to_string(first) + " bytes, uncompressed_size says " +
                        std::to_string(uncompressed_size));
    DecompressContext d;
    if (!d.ctx) return fail(MessageErrorType::OperationFailed, "zstd: cannot create a decompression context");
    ZSTD_DCtx_setParameter(d.ctx, ZSTD_d_windowLogMax, kMaxWindowLog);
    // The output grows as zstd produces it, never past uncompressed_size: the announced size is
    // allocated only once the data has proven it (16 KiB of zstd can announce 500 MiB of zeros).
    const std::uint64_t start = std::max<std::uint64_t>(256 * 1024, 4 * static_cast<std::uint64_t>(records.size()));
    std::vector<std::byte> out(static_cast<std::size_t>(std::min(uncompressed_size, start)));
    ZSTD_inBuffer in{records.data(), records.size(), 0};
    std::size_t produced = 0;
    for (;;) {
        ZSTD_outBuffer ob{out.data(), out.size(), produced};
        const std::size_t in_before = in.pos;
        const std::size_t ret = ZSTD_decompressStream(d.ctx, &ob, &in);
        if (ZSTD_isError(ret)) return fail(MessageErrorType::DataSerializationError, std::string("zstd: ") + ZSTD_getErrorName(ret));
        const bool progress = ob.pos != produced || in.pos != in_before;
        produced = ob.pos;
        if (ret == 0 && in.pos == in.size) break;  // the last frame is complete and every byte used
        if (produced == out.size() && out.size() < uncompressed_size) {
            out.resize(static_cast<std::size_t>(std::min<std::uint64_t>(uncompressed_size, 2 * static_cast<std::uint64_t>(out.size()))));
            continue;
        }
        if (!progress) {
            if (produced == out.size())
                return fail(MessageErrorType::DataSerializationError,
                            "zstd output exceeds uncompressed_size " + std::to_string(uncompressed_size));
            return fail(MessageErrorType::DataSerializationError, "zstd data ends inside a frame");
        }
    }
    if (produced != uncompressed_size)
        return fail(MessageErrorType::DataSerializationError, "zstd output is " + std::to_string(produced) +
                                                                  " bytes, uncompressed_size says " +
                                                                  std::to_string(uncompressed_size));
    return out;
}

}  // namespace rr::mcap::detail
