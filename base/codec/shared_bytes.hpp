// SharedBytes: an immutable byte range plus the owner that keeps it alive.
//
// Decoded MessageElements point into the receive buffer through SharedBytes (no copy); copying a
// SharedBytes bumps a reference count and never copies the bytes. Element payloads built locally own a
// vector through the same type, so readers never care where the bytes came from.
#pragma once

#include <cstddef>
#include <cstring>
#include <memory>
#include <span>
#include <vector>

namespace rr {

class SharedBytes {
public:
    SharedBytes() = default;
    SharedBytes(std::shared_ptr<const void> owner, std::span<const std::byte> bytes)
        : owner_(std::move(owner)), bytes_(bytes) {}

    /// Takes ownership of `data` (one allocation for the shared control block).
    static SharedBytes adopt(std::vector<std::byte>&& data) {
        auto holder = std::make_shared<const std::vector<std::byte>>(std::move(data));
        std::span<const std::byte> view(holder->data(), holder->size());
        return SharedBytes(std::move(holder), view);
    }
    /// Copies `data` into a new owned buffer.
    static SharedBytes copy_of(std::span<const std::byte> data) {
        return adopt(std::vector<std::byte>(data.begin(), data.end()));
    }
    static SharedBytes copy_of(const void* data, std::size_t n) {
        return copy_of(std::span<const std::byte>(static_cast<const std::byte*>(data), n));
    }

    std::span<const std::byte> bytes() const noexcept { return bytes_; }
    const std::byte* data() const noexcept { return bytes_.data(); }
    std::size_t size() const noexcept { return bytes_.size(); }
    bool empty() const noexcept { return bytes_.empty(); }
    /// What keeps the bytes alive; null for a view of memory the caller keeps alive.
    const std::shared_ptr<const void>& owner() const noexcept { return owner_; }

    /// A view of [offset, offset+n) sharing the same owner. Precondition: in range.
    SharedBytes subspan(std::size_t offset, std::size_t n) const { return SharedBytes(owner_, bytes_.subspan(offset, n)); }

    friend bool operator==(const SharedBytes& a, const SharedBytes& b) noexcept {
        return a.size() == b.size() && (a.size() == 0 || std::memcmp(a.data(), b.data(), a.size()) == 0);
    }

private:
    std::shared_ptr<const void> owner_;
    std::span<const std::byte> bytes_;
};

}  // namespace rr
