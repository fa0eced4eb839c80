// HandlerMemory: where Asio allocates the operations of one connection (its pump's post, dispatch,
// wake and write, a JSON WebSocket's wake and write, and the strand hand-offs of their completions)
// instead of the heap. Asio's own recycling cache is per thread, and a connection's operations are
// often made on one thread and freed on another (a value fanned out by the device's strand to each
// client's strand), so that cache misses on every one of them (issue 14, bench/profile.sh's raw RR
// fan-out). Here a connection has a few blocks, each kept after its first use and handed out again
// while free and large enough; requests beyond them go to the heap. Used through HandlerAllocator
// with asio::bind_allocator.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <new>

namespace rr::server {

class HandlerMemory {
public:
    /// A new memory, referenced once by its owner (give that reference back with release()).
    static HandlerMemory* make() { return new HandlerMemory(); }
    HandlerMemory(const HandlerMemory&) = delete;
    HandlerMemory& operator=(const HandlerMemory&) = delete;

    /// The owner's reference. Every allocation holds one too, so the memory outlives its owner until
    /// Asio has given back the last block (an operation destroyed after the connection). Copies of
    /// the allocator may outlive it: Asio's strand keeps one in its invoker but does not allocate with
    /// it after the operation that made the invoker has been freed.
    void release() noexcept { unref(); }

    /// `size` bytes aligned for any standard type: a free kept block that is large enough, or a free
    /// slot given a new block of `size`, or else the heap. Thread-safe. Throws std::bad_alloc.
    void* allocate(std::size_t size);
    /// Gives back what allocate() returned, on any thread.
    void deallocate(void* p) noexcept;

    /// Allocations the blocks could not serve (all in use), since construction.
    std::uint64_t heap_allocations() const noexcept { return heap_.load(std::memory_order_relaxed); }
    /// Blocks made or replaced (a slot's first use, or a larger request), since construction.
    std::uint64_t block_allocations() const noexcept { return blocks_made_.load(std::memory_order_relaxed); }

    /// Slots: a pump has up to a write and a wake pending, each with a strand hand-off, and usually a
    /// post or dispatch or two (more of those at once take the heap).
    static constexpr std::size_t kSlots = 6;

private:
    HandlerMemory() = default;
    ~HandlerMemory();
    void unref() noexcept;

    struct Slot {
        std::atomic<bool> used{false};
        std::atomic<void*> block{nullptr};  // read unclaimed by deallocate(); written only by the claimer
        std::size_t capacity = 0;           // the claimer's
    };
    std::array<Slot, kSlots> slots_{};
    std::atomic<std::size_t> refs_{1};
    std::atomic<std::uint64_t> heap_{0}, blocks_made_{0};
};

/// The standard allocator over a HandlerMemory (bind it with asio::bind_allocator). Types aligned
/// beyond operator new's default alignment come from the heap.
template <class T>
class HandlerAllocator {
public:
    using value_type = T;

    explicit HandlerAllocator(HandlerMemory* memory) noexcept : memory_(memory) {}
    template <class U>
    HandlerAllocator(const HandlerAllocator<U>& other) noexcept : memory_(other.memory()) {}

    T* allocate(std::size_t n) {
        if constexpr (alignof(T) > __STDCPP_DEFAULT_NEW_ALIGNMENT__)
            return static_cast<T*>(::operator new(n * sizeof(T), std::align_val_t{alignof(T)}));
        else
            return static_cast<T*>(memory_->allocate(n * sizeof(T)));
    }
    void deallocate(T* p, std::size_t) noexcept {
        if constexpr (alignof(T) > __STDCPP_DEFAULT_NEW_ALIGNMENT__)
            ::operator delete(p, std::align_val_t{alignof(T)});
        else
            memory_->deallocate(p);
    }

    HandlerMemory* memory() const noexcept { return memory_; }
    template <class U>
    bool operator==(const HandlerAllocator<U>& other) const noexcept { return memory_ == other.memory(); }

private:
    HandlerMemory* memory_;
};

/// A connection's own HandlerMemory: gives the owner's reference back when destroyed. Make it the
/// connection's first member, so it goes last, after the stream has destroyed what it still held.
class ConnectionHandlerMemory {
public:
    ConnectionHandlerMemory() : memory_(HandlerMemory::make()) {}
    ~ConnectionHandlerMemory() { memory_->release(); }
    ConnectionHandlerMemory(const ConnectionHandlerMemory&) = delete;
    ConnectionHandlerMemory& operator=(const ConnectionHandlerMemory&) = delete;

    /// For asio::bind_allocator on the connection's operations.
    HandlerAllocator<void> allocator() const noexcept { return HandlerAllocator<void>(memory_); }

private:
    HandlerMemory* memory_;
};

}  // namespace rr::server
