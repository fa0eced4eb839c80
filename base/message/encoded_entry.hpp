// EncodedEntry: one message entry that many messages carry unchanged (a wire value or an event sent to
// every client session of a service, or fanned out by the gateway). Each message format's bytes of the
// entry are made once, on first use, and follow every message's own header (encode_message with an
// encoded entry), instead of encoding the entry's elements again per session: copied when small,
// spliced into the session's gathered write when large and the entry is held by a shared_ptr.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <vector>

#include "base/error/rr_error.hpp"
#include "base/message/message.hpp"

namespace rr {

class EncodedEntry : public std::enable_shared_from_this<EncodedEntry> {
public:
    explicit EncodedEntry(MessageEntry entry) : entry_(std::move(entry)) {}
    EncodedEntry(const EncodedEntry&) = delete;
    EncodedEntry& operator=(const EncodedEntry&) = delete;
    virtual ~EncodedEntry() = default;

    const MessageEntry& entry() const noexcept { return entry_; }

    /// The entry encoded in message format `version` (2 or 4; encode_entry), made on the first call for
    /// that format and kept for the entry's life. Thread-safe. Errors: as encode_entry (a v2 string over
    /// 65535 bytes, an element that cannot travel, …), the same error on every call; InvalidArgument
    /// for another version.
    Result<std::span<const std::byte>> bytes(std::uint16_t version) const;
    /// The same bytes, kept alive by this entry when a shared_ptr owns it and they are at least
    /// `owned_from` bytes (else a view without owner, valid while the entry lives: what a caller that
    /// copies small entries wants, without the owner's reference count). Errors: as bytes().
    Result<SharedBytes> shared_bytes(std::uint16_t version, std::size_t owned_from = 0) const;

private:
    struct Encoding {
        std::once_flag once;
        std::vector<std::byte> bytes;
        std::optional<RRError> error;
    };

    const MessageEntry entry_;
    mutable Encoding v2_, v4_;
};

}  // namespace rr
