// EntryVectorPool: emptied Message::entries vectors kept for the next message of a connection.
//
// A call costs a connection two entry vectors: the received message's and the reply's. Handing the
// received one back once its entries are handled, and the sent one once it is encoded, lets the next
// call reuse both instead of allocating (issue 14, bench/profile.sh). Bounded: at most kMaxVectors
// vectors of at most kMaxCapacity entries are kept; anything else is freed. Not thread-safe (one per
// connection, used on its strand).
#pragma once

#include <array>
#include <cstddef>
#include <utility>
#include <vector>

#include "core/message/message.hpp"

namespace rr {

class EntryVectorPool {
public:
    static constexpr std::size_t kMaxVectors = 4;
    static constexpr std::size_t kMaxCapacity = 4;

    /// An empty vector: a kept one (its capacity reused), or a new one when none is kept.
    std::vector<MessageEntry> take() noexcept {
        if (count_ == 0) return {};
        return std::move(spare_[--count_]);
    }

    /// Destroys the entries of `entries` (their payload owners are released now) and keeps the
    /// vector's storage when there is room and it is small.
    void give(std::vector<MessageEntry>&& entries) noexcept {
        entries.clear();
        if (count_ == kMaxVectors || entries.capacity() == 0 || entries.capacity() > kMaxCapacity) {
            std::vector<MessageEntry>().swap(entries);
            return;
        }
        spare_[count_++] = std::move(entries);
    }

    /// Vectors kept now.
    std::size_t size() const noexcept { return count_; }

private:
    std::array<std::vector<MessageEntry>, kMaxVectors> spare_;
    std::size_t count_ = 0;
};

}  // namespace rr
