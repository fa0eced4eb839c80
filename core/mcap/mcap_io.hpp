// Where MCAP bytes go to and come from: the writer appends to a Sink, the reader reads a Source at
// offsets. core/ implements both over memory; server/mcap/mcap_file.hpp implements them over files.
//
// Errors from an implementation are returned as they are (use IOError for an operating-system failure,
// with the path and errno text in the message); the writer and reader add nothing to them.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <vector>

#include "base/error/rr_error.hpp"

namespace rr::mcap {

/// Append-only byte sink. Not required to be thread-safe: one writer uses it at a time.
class Sink {
public:
    virtual ~Sink() = default;
    /// Appends all of `bytes` or fails.
    virtual Result<void> write(std::span<const std::byte> bytes) = 0;
    /// Pushes written bytes towards durable storage (the writer calls it after each complete chunk
    /// and at close); a memory sink does nothing.
    virtual Result<void> flush() { return {}; }
};

/// Random-access byte source of a known size. Not required to be thread-safe.
class Source {
public:
    virtual ~Source() = default;
    /// Size in bytes (a file's size when it was opened).
    virtual std::uint64_t size() const = 0;
    /// Fills `out` with the bytes at [offset, offset + out.size()); fails (IOError) when that range is
    /// not wholly inside size() or the read fails.
    virtual Result<void> read_at(std::uint64_t offset, std::span<std::byte> out) = 0;
};

/// Sink into a vector owned by the caller (tests, the fuzz target, in-memory recordings).
class VectorSink final : public Sink {
public:
    explicit VectorSink(std::vector<std::byte>& out) : out_(out) {}
    Result<void> write(std::span<const std::byte> bytes) override {
        out_.insert(out_.end(), bytes.begin(), bytes.end());
        return {};
    }

private:
    std::vector<std::byte>& out_;
};

/// Source over memory the caller keeps alive for the Source's lifetime.
class SpanSource final : public Source {
public:
    explicit SpanSource(std::span<const std::byte> bytes) : bytes_(bytes) {}
    std::uint64_t size() const override { return bytes_.size(); }
    Result<void> read_at(std::uint64_t offset, std::span<std::byte> out) override {
        if (offset > bytes_.size() || out.size() > bytes_.size() - offset)
            return fail(MessageErrorType::IOError, "mcap: read past the end of the buffer");
        if (!out.empty()) std::memcpy(out.data(), bytes_.data() + offset, out.size());
        return {};
    }

private:
    std::span<const std::byte> bytes_;
};

}  // namespace rr::mcap
