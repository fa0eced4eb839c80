// The FIFO in which a sans-IO session leaves its events for the host (StreamConnection,
// ServiceSession, ClientSession). A message makes one or two events, taken at once; a vector reused
// from the front keeps its storage, where std::deque allocated a block every few messages.
#pragma once

#include <cstddef>
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

private:
    std::vector<T> items_;
    std::size_t head_ = 0;
};

}  // namespace rr
