// What waits for each outstanding request, by request id. A std::map whose erased nodes are kept (a
// few) and reused by the next insert: a request/reply pair allocates no map node in steady state
// (issue 14, bench/profile.sh).
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <utility>
#include <vector>

namespace rr {

/// A map from request id to `V` (default-constructible, movable). Iteration is in id order.
/// Up to `kSpareNodes` erased nodes are kept for reuse; their values are reset to `V{}` at once, so
/// whatever a value holds (a completion, its captures) is released when its entry goes.
template <class V>
class RequestMap {
public:
    using Map = std::map<std::uint32_t, V>;
    using iterator = typename Map::iterator;
    using const_iterator = typename Map::const_iterator;
    static constexpr std::size_t kSpareNodes = 8;

    /// Sets `id`'s value (replacing one already there). One search of the tree either way.
    void put(std::uint32_t id, V value) {
        if (spare_.empty()) {
            map_.insert_or_assign(id, std::move(value));
            return;
        }
        auto node = std::move(spare_.back());
        spare_.pop_back();
        node.key() = id;
        node.mapped() = std::move(value);
        auto r = map_.insert(std::move(node));
        if (r.inserted) return;
        r.position->second = std::move(r.node.mapped());  // `id` was there: the node goes back
        r.node.mapped() = V{};
        spare_.push_back(std::move(r.node));
    }

    iterator find(std::uint32_t id) { return map_.find(id); }
    const_iterator find(std::uint32_t id) const { return map_.find(id); }
    iterator begin() { return map_.begin(); }
    iterator end() { return map_.end(); }
    const_iterator begin() const { return map_.begin(); }
    const_iterator end() const { return map_.end(); }
    bool empty() const noexcept { return map_.empty(); }
    std::size_t size() const noexcept { return map_.size(); }

    /// Removes the entry at `it` (not end()) and returns its value.
    V take(iterator it) {
        V value = std::move(it->second);
        erase(it);
        return value;
    }

    /// Removes the entry at `it` (not end()); returns the iterator after it.
    iterator erase(iterator it) {
        auto next = std::next(it);
        auto node = map_.extract(it);
        node.mapped() = V{};
        if (spare_.size() < kSpareNodes) {
            if (spare_.capacity() == 0) spare_.reserve(kSpareNodes);
            spare_.push_back(std::move(node));
        }
        return next;
    }

    /// Removes `id`'s entry if there is one.
    void erase(std::uint32_t id) {
        if (auto it = map_.find(id); it != map_.end()) erase(it);
    }

    /// Removes every entry (nodes are freed, not kept).
    void clear() { map_.clear(); }

    /// Nodes kept for reuse (for tests).
    std::size_t spare_nodes() const noexcept { return spare_.size(); }

private:
    Map map_;
    std::vector<typename Map::node_type> spare_;
};

}  // namespace rr
