// NodeID: the 128-bit UUID naming a Robot Raconteur node (wire.md §1.1).
// On the wire it is 16 bytes in RFC 4122 order (the order of the hex digits of the text form).
#pragma once

#include <array>
#include <cstddef>
#include <cstring>
#include <string>
#include <string_view>

#include "base/error/rr_error.hpp"

namespace rr {

class NodeID {
public:
    using Bytes = std::array<std::byte, 16>;

    NodeID() = default;  ///< the all-zero NodeID: "any node / unknown"
    explicit NodeID(const Bytes& bytes) : bytes_(bytes) {}

    /// Parses "{8-4-4-4-12}", "8-4-4-4-12" or 32 hex digits (upper or lower case), as in connection URLs.
    /// Errors: InvalidArgument.
    static Result<NodeID> parse(std::string_view text);

    const Bytes& bytes() const noexcept { return bytes_; }
    bool is_any() const noexcept { return *this == NodeID(); }

    /// Lower-case "xxxxxxxx-xxxx-xxxx-xxxx-xxxxxxxxxxxx" without braces.
    std::string to_string() const;
    /// Lower-case "{xxxxxxxx-xxxx-xxxx-xxxx-xxxxxxxxxxxx}" (the form CORE prints).
    std::string to_braced_string() const;

    /// One 16-byte memcmp (compilers inline it as two word compares; the element-wise default was a
    /// byte loop, and every sent and received message compares NodeIDs).
    friend bool operator==(const NodeID& a, const NodeID& b) noexcept {
        return std::memcmp(a.bytes_.data(), b.bytes_.data(), sizeof(Bytes)) == 0;
    }
    /// Byte-wise order (for maps); spelled out because libc++ 14 (Emscripten) has no <=> for std::array.
    friend bool operator<(const NodeID& a, const NodeID& b) noexcept {
        for (std::size_t i = 0; i < a.bytes_.size(); ++i)
            if (a.bytes_[i] != b.bytes_[i]) return a.bytes_[i] < b.bytes_[i];
        return false;
    }

private:
    Bytes bytes_{};
};

}  // namespace rr
