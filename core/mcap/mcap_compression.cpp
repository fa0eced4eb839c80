#include "core/mcap/mcap_compression.hpp"

#include <zstd.h>

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
    // A first frame that announces more than the whole chunk is wrong: say so before allocating.
    const unsigned long long first = ZSTD_getFrameContentSize(records.data(), records.size());
    if (first == ZSTD_CONTENTSIZE_ERROR)
        return fail(MessageErrorType::DataSerializationError, "records are not zstd data");
    if (first != ZSTD_CONTENTSIZE_UNKNOWN && first > uncompressed_size)
        return fail(MessageErrorType::DataSerializationError,
                    "zstd frame announces " + std::to_string(first) + " bytes, uncompressed_size says " +
                        std::to_string(uncompressed_size));
    // The announced size bounds the output: zstd stops with an error rather than write past it.
    std::vector<std::byte> out(static_cast<std::size_t>(uncompressed_size));
    std::size_t n = ZSTD_decompress(out.data(), out.size(), records.data(), records.size());
    if (ZSTD_isError(n))
        return fail(MessageErrorType::DataSerializationError, std::string("zstd: ") + ZSTD_getErrorName(n));
    if (n != uncompressed_size)
        return fail(MessageErrorType::DataSerializationError, "zstd output is " + std::to_string(n) +
                                                                  " bytes, uncompressed_size says " +
                                                                  std::to_string(uncompressed_size));
    return out;
}

}  // namespace rr::mcap::detail
