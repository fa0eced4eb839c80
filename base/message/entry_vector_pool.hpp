// EntryVectorPool: emptied Message::entries vectors, and the element vectors of sent entries, kept
// for the next message of a connection.
//
// A call costs a connection two entry vectors: the received message's and the reply's. Handing the
// received one back once its entries are handled, and the sent one once it is encoded, lets the next
// call reuse both instead of allocating (issue 14, bench/profile.sh). The reply's element vector comes
// back the same way: a service session hands it to the next request that has none, and the service
// builds that request's reply in it. Bounded: at most kMaxVectors entry vectors of at most
// kMaxCapacity entries and kMaxVectors element vectors of at most kMaxElementCapacity elements are
// kept; anything else is freed. Not thread-safe (one per connection, used on its strand).
#pragma once

#include <array>
#include <cstddef>
#include <utility>
#include <vector>

#include "base/message/message.hpp"

namespace rr {

class EntryVectorPool {
public:
    static constexpr std::size_t kMaxVectors = 4;
    static constexpr std::size_t kMaxCapacity = 4;
    static constexpr std::size_t kMaxElementCapacity = 8;

    /// An empty vector: a kept one (its capacity reused), or a new one when none is kept.
    std::vector<MessageEntry> take() noexcept {
        if (count_ == 0) return {};
        return std::move(spare_[--count_]);
    }

    /// An empty element vector: a kept one (its capacity reused), or a new one when none is kept.
    std::vector<MessageElement> take_elements() noexcept {
        if (element_count_ == 0) return {};
        return std::move(spare_elements_[--element_count_]);
    }

    /// Destroys the entries of `entries` (their payload owners are released now) and keeps the
    /// vector's storage, and that of their element vectors, when there is room and it is small.
    void give(std::vector<MessageEntry>&& entries) noexcept {
        for (auto& entry : entries) keep_elements(entry.elements);
        entries.clear();
        if (count_ == kMaxVectors || entries.capacity() == 0 || entries.capacity() > kMaxCapacity) {
            std::vector<MessageEntry>().swap(entries);
            return;
        }
        spare_[count_++] = std::move(entries);
    }

    /// Keeps the storage of a sent entry's element vector (emptied here) when there is room and it is small.
    void give_elements(std::vector<MessageElement>&& elements) noexcept { keep_elements(elements); }

    /// Entry vectors kept now.
    std::size_t size() const noexcept { return count_; }
    /// Element vectors kept now.
    std::size_t element_vectors() const noexcept { return element_count_; }

private:
    void keep_elements(std::vector<MessageElement>& elements) noexcept {
        if (element_count_ == kMaxVectors || elements.capacity() == 0 || elements.capacity() > kMaxElementCapacity) return;
        elements.clear();
        spare_elements_[element_count_++] = std::move(elements);
    }

    std::array<std::vector<MessageEntry>, kMaxVectors> spare_;
    std::size_t count_ = 0;
    std::array<std::vector<MessageElement>, kMaxVectors> spare_elements_;
    std::size_t element_count_ = 0;
};

}  // namespace rr
