// The FIFO in which a sans-IO session leaves its events for the host (StreamConnection,
// ServiceSession, ClientSession). A message makes one or two events, taken at once; a vector reused
// from the front keeps its storage, where std::deque allocated a block every few messages.
// take_all() hands a host every event at once, to handle in place.
#pragma once

#include <cstddef>
#include <iterator>
#include <optional>
#include <utility>
#include <vector>

namespace rr {

template <class T>
class EventQueue {
public:
    template <class... Args>
    T& emplace_back(Args&&... args) {
        return items_.emplace_back(std::forward<Args>(args)...);
    }
    void push_back(T value) { items_.push_back(std::move(value)); }
    /// Removes the newest event (one just emplaced that turned out not to be needed).
    void pop_back() { items_.pop_back(); }
    bool empty() const noexcept { return head_ == items_.size(); }
    std::size_t size() const noexcept { return items_.size() - head_; }

    /// The oldest event, moved out; nullopt when there is none.
    std::optional<T> pop() {
        std::optional<T> out;  // every path returns `out`: the compiler builds it in the caller's slot
        if (empty()) return out;
        out.emplace(std::move(items_[head_++]));
        if (empty()) {
            items_.clear();  // keeps the capacity
            head_ = 0;
        } else if (head_ >= 64 && head_ * 2 >= items_.size()) {
            // A host that never drains completely: drop the taken prefix now and then.
            items_.erase(items_.begin(), items_.begin() + static_cast<std::ptrdiff_t>(head_));
            head_ = 0;
        }
        return out;
    }

    /// Moves every queued event into `batch` (whose old events are destroyed first), oldest first, so
    /// that a host handles them where they are instead of moving each one out as pop() does. The two
    /// vectors swap storage, so both keep their capacity from one drain to the next.
    void take_all(std::vector<T>& batch) {
        batch.clear();
        if (head_ == 0) {
            std::swap(batch, items_);
            return;
        }
        batch.insert(batch.end(), std::make_move_iterator(items_.begin() + static_cast<std::ptrdiff_t>(head_)),
                     std::make_move_iterator(items_.end()));
        items_.clear();
        head_ = 0;
    }

private:
    std::vector<T> items_;
    std::size_t head_ = 0;
};

}  // namespace rr
