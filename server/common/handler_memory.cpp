#include "server/common/handler_memory.hpp"

namespace rr::server {

HandlerMemory::~HandlerMemory() {
    for (auto& s : slots_) ::operator delete(s.block.load(std::memory_order_relaxed));
}

void HandlerMemory::unref() noexcept {
    if (refs_.fetch_sub(1, std::memory_order_acq_rel) == 1) delete this;
}

void* HandlerMemory::allocate(std::size_t size) {
    refs_.fetch_add(1, std::memory_order_relaxed);
    Slot* spare = nullptr;  // a free slot whose block is too small, claimed; one without a block preferred
    for (auto& s : slots_) {
        if (s.used.load(std::memory_order_relaxed) || s.used.exchange(true, std::memory_order_acquire)) continue;
        if (s.capacity >= size) {
            if (spare) spare->used.store(false, std::memory_order_release);
            return s.block.load(std::memory_order_relaxed);
        }
        if (!spare) {
            spare = &s;
        } else if (spare->capacity != 0 && s.capacity == 0) {
            spare->used.store(false, std::memory_order_release);
            spare = &s;
        } else {
            s.used.store(false, std::memory_order_release);
        }
    }
    try {
        if (!spare) {
            heap_.fetch_add(1, std::memory_order_relaxed);
            return ::operator new(size);
        }
        // The new block is published before the old one is freed: deallocate() never matches a
        // pointer the heap may hand out again.
        void* block = ::operator new(size);
        ::operator delete(spare->block.exchange(block, std::memory_order_acq_rel));
        spare->capacity = size;
        blocks_made_.fetch_add(1, std::memory_order_relaxed);
        return block;
    } catch (...) {
        if (spare) spare->used.store(false, std::memory_order_release);
        unref();
        throw;
    }
}

void HandlerMemory::deallocate(void* p) noexcept {
    bool from_slot = false;
    for (auto& s : slots_) {
        if (s.block.load(std::memory_order_acquire) == p) {
            s.used.store(false, std::memory_order_release);
            from_slot = true;
            break;
        }
    }
    if (!from_slot) ::operator delete(p);
    unref();
}

}  // namespace rr::server
