// The recorder's queue between the live path and the writer thread (docs/recording.md "What it costs").
//
// The live path hands over the reference it already has: the SharedEntry the gateway fans out to its
// clients (one atomic increment, no copy of the entry's bytes). Each item weighs its payload bytes plus a
// fixed overhead; when the items waiting would exceed the budget the new one is dropped and counted, so
// the live path never waits for the disk. The items the writer has taken count until it comes back for
// more (its batch written and released): the queue and the writer's batch together never hold more
// than the budget. The items live in a vector whose capacity is kept from batch
// to batch (swapped with the writer's), so a warmed-up queue allocates nothing per value, and the writer
// is not woken per value: it takes what waits every `period`, or early once the queue is half full or
// closed (one notify per crossing), so the live path makes no futex call per value either.
//
// Thread-safe: offer() from any thread; take() from one writer thread.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <vector>

#include "server/gateway/shared_entry.hpp"

namespace rr::server::record {

class RecordQueue {
public:
    struct Item {
        std::uint16_t member = 0;      ///< index into the recording's members
        std::uint64_t log_ns = 0;      ///< the gateway's receive time, ns since the Unix epoch
        gateway::SharedEntryPtr entry; ///< the entry the live path shares (not a copy)
        std::size_t bytes = 0;         ///< its weight in the budget (weight())
    };
    enum class Offered : std::uint8_t { queued, dropped, closed, stale };

    /// `budget_bytes`: the most the waiting items may weigh (RecordingSpec::queue_bytes).
    explicit RecordQueue(std::size_t budget_bytes) : budget_(budget_bytes) {}

    /// From the live path: queues `entry` (the reference is kept, the bytes are not copied), or drops
    /// it (counted in drops()) when it would exceed the budget, or ignores it once closed.
    Offered offer(std::uint16_t member, std::uint64_t log_ns, gateway::SharedEntryPtr entry);
    /// offer() for a wire's value: `stale` (not queued, not a drop) when it arrived before the newest
    /// value offered for `member` (SharedEntry::arrival): a wire's newest, handed to a subscriber joining
    /// it, can come after a newer value, and a wire keeps only its newest.
    Offered offer_newest(std::uint16_t member, std::uint64_t log_ns, gateway::SharedEntryPtr entry);

    /// From the writer: the previous batch is done (its weight leaves the budget; `batch` must be empty,
    /// its capacity is reused); waits until `period` has passed, the queue is half full or closed, then
    /// swaps what waits into `batch`, whose weight counts until the next take(). Returns true when the
    /// queue was closed at the swap: `batch` then holds the last items there will be.
    bool take(std::vector<Item>& batch, std::chrono::milliseconds period);

    /// No more offers; wakes the writer.
    void close();
    /// Closes and forgets what waits (a failed recording).
    void close_and_clear();

    std::uint64_t drops() const;
    /// The weight waiting plus the weight of the batch the writer holds.
    std::size_t queued_bytes() const;
    std::size_t budget_bytes() const noexcept { return budget_; }

    /// What an entry weighs: its elements' payload bytes plus 64 bytes per element and 128 per entry.
    static std::size_t weight(const MessageEntry& entry) noexcept;

private:
    Offered offer(std::uint16_t member, std::uint64_t log_ns, gateway::SharedEntryPtr entry, bool newest_only);

    const std::size_t budget_;
    mutable std::mutex mutex_;
    std::condition_variable wake_;
    std::vector<Item> items_;
    std::size_t queued_bytes_ = 0;  // items_ and the writer's batch
    std::size_t taken_bytes_ = 0;   // the writer's batch
    std::uint64_t drops_ = 0;
    std::vector<std::uint64_t> newest_arrival_;  // per member, for offer_newest()
    bool closed_ = false;
};

}  // namespace rr::server::record
