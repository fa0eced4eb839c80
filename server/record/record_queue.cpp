#include "server/record/record_queue.hpp"

namespace rr::server::record {

namespace {

std::size_t elements_weight(const std::vector<MessageElement>& elements) noexcept {
    std::size_t n = 0;
    for (const auto& e : elements) n += 64 + e.data.size() + elements_weight(e.elements);
    return n;
}

}  // namespace

std::size_t RecordQueue::weight(const MessageEntry& entry) noexcept { return 128 + elements_weight(entry.elements); }

RecordQueue::Offered RecordQueue::offer(std::uint16_t member, std::uint64_t log_ns, gateway::SharedEntryPtr entry) {
    return offer(member, log_ns, std::move(entry), false);
}

RecordQueue::Offered RecordQueue::offer_newest(std::uint16_t member, std::uint64_t log_ns, gateway::SharedEntryPtr entry) {
    return offer(member, log_ns, std::move(entry), true);
}

RecordQueue::Offered RecordQueue::offer(std::uint16_t member, std::uint64_t log_ns, gateway::SharedEntryPtr entry,
                                        bool newest_only) {
    const std::size_t bytes = weight(entry->entry());
    const std::size_t half = budget_ / 2;
    bool wake = false;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        if (closed_) return Offered::closed;
        if (newest_only) {
            if (newest_arrival_.size() <= member) newest_arrival_.resize(member + 1u, 0);  // once per member
            if (entry->arrival() <= newest_arrival_[member]) return Offered::stale;
            newest_arrival_[member] = entry->arrival();
        }
        if (queued_bytes_ + bytes > budget_) {
            ++drops_;
            return Offered::dropped;
        }
        // The writer is woken once, when the queue crosses half its budget; otherwise it wakes on its period.
        wake = queued_bytes_ < half && queued_bytes_ + bytes >= half;
        queued_bytes_ += bytes;
        items_.push_back(Item{member, log_ns, std::move(entry), bytes});
    }
    if (wake) wake_.notify_one();
    return Offered::queued;
}

bool RecordQueue::take(std::vector<Item>& batch, std::chrono::milliseconds period) {
    std::unique_lock<std::mutex> lock(mutex_);
    queued_bytes_ -= taken_bytes_;  // the writer is done with its last batch
    taken_bytes_ = 0;
    wake_.wait_for(lock, period, [&] { return closed_ || queued_bytes_ >= budget_ / 2; });
    batch.swap(items_);
    taken_bytes_ = queued_bytes_;
    return closed_;
}

void RecordQueue::close() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        closed_ = true;
    }
    wake_.notify_all();
}

void RecordQueue::close_and_clear() {
    std::vector<Item> gone;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        closed_ = true;
        gone.swap(items_);
        queued_bytes_ = taken_bytes_;
    }
    wake_.notify_all();
    // `gone` releases its entries here, outside the lock.
}

std::uint64_t RecordQueue::drops() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return drops_;
}

std::size_t RecordQueue::queued_bytes() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return queued_bytes_;
}

}  // namespace rr::server::record
