// GatherBuffer: bytes to write as one stream, made of owned bytes with shared byte ranges spliced in.
//
// A large payload that already lives in a shared buffer (a received frame's array, a value encoded
// once for every subscriber, EncodedEntry) is recorded as a splice instead of being copied: the
// transport writes the pieces with one gathered write (writev). Below kSpliceMinBytes a copy costs
// less than the reference count and the iovec entry a splice needs, so such ranges are copied.
// Not thread-safe.
#pragma once

#include <cstddef>
#include <span>
#include <utility>
#include <vector>

#include "base/codec/shared_bytes.hpp"

namespace rr {

class GatherBuffer {
public:
    /// Shared ranges this size and larger are spliced, smaller ones copied (bytes).
    static constexpr std::size_t kSpliceMinBytes = 4096;

    /// `bytes` goes into the stream just before owned byte `at` (at == owned size: at the end so far).
    struct Splice {
        std::size_t at;
        SharedBytes bytes;
    };

    /// A position to roll back to (an append that failed or went over a limit).
    struct Mark {
        std::size_t owned;
        std::size_t splices;
        std::size_t spliced;
        /// The buffer's size() when the mark was taken.
        std::size_t size() const noexcept { return owned + spliced; }
    };

    /// Whether append() splices `bytes` rather than copying it.
    static bool splices(const SharedBytes& bytes) noexcept {
        return bytes.size() >= kSpliceMinBytes && bytes.owner() != nullptr;
    }

    /// The owned bytes (without the splices), for appending.
    std::vector<std::byte>& owned() noexcept { return owned_; }
    const std::vector<std::byte>& owned() const noexcept { return owned_; }
    const std::vector<Splice>& splices() const noexcept { return splices_; }

    /// Bytes in the stream: owned plus spliced.
    std::size_t size() const noexcept { return owned_.size() + spliced_; }
    bool empty() const noexcept { return owned_.empty() && splices_.empty(); }
    /// Bytes in splices.
    std::size_t spliced_bytes() const noexcept { return spliced_; }

    void append(std::span<const std::byte> bytes) { owned_.insert(owned_.end(), bytes.begin(), bytes.end()); }
    /// Appends `bytes`: spliced when it is at least kSpliceMinBytes and has an owner that keeps it alive
    /// (an ownerless view may die with its caller), else copied.
    void append(const SharedBytes& bytes) {
        if (splices(bytes)) {
            splices_.push_back(Splice{owned_.size(), bytes});
            spliced_ += bytes.size();
        } else {
            append(bytes.bytes());
        }
    }

    Mark mark() const noexcept { return Mark{owned_.size(), splices_.size(), spliced_}; }
    /// Drops everything appended after `m`.
    void rollback(const Mark& m) {
        owned_.resize(m.owned);
        splices_.resize(m.splices);
        spliced_ = m.spliced;
    }

    /// Empties the buffer, keeping its capacity; releases the spliced ranges.
    void clear() noexcept {
        owned_.clear();
        if (!splices_.empty()) {  // the common case has none: no call into the vector's erase
            splices_.clear();
            spliced_ = 0;
        }
    }
    void swap(GatherBuffer& other) noexcept {
        owned_.swap(other.owned_);
        if (splices_.empty() && other.splices_.empty()) return;  // the common case: both keep their capacity
        splices_.swap(other.splices_);
        std::swap(spliced_, other.spliced_);
    }

    /// Calls `fn(std::span<const std::byte>)` for each non-empty piece in stream order.
    template <class Fn>
    void for_each_piece(Fn&& fn) const {
        std::size_t from = 0;
        for (const auto& s : splices_) {
            if (s.at > from) fn(std::span<const std::byte>(owned_).subspan(from, s.at - from));
            fn(s.bytes.bytes());
            from = s.at;
        }
        if (owned_.size() > from) fn(std::span<const std::byte>(owned_).subspan(from));
    }

    /// Turns the splices into owned bytes (one copy of the spliced ranges).
    void flatten() {
        if (splices_.empty()) return;
        std::vector<std::byte> flat;
        flat.reserve(size());
        for_each_piece([&](std::span<const std::byte> piece) { flat.insert(flat.end(), piece.begin(), piece.end()); });
        owned_.swap(flat);
        splices_.clear();
        spliced_ = 0;
    }

private:
    std::vector<std::byte> owned_;
    std::vector<Splice> splices_;
    std::size_t spliced_ = 0;
};

}  // namespace rr
