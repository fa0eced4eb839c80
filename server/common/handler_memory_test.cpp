// HandlerMemory: blocks kept and handed out again, the heap beyond them, lifetime past the owner, and
// Asio's strand hand-offs between threads served without the heap.
#include <catch2/catch.hpp>

#include <atomic>
#include <functional>
#include <future>
#include <thread>
#include <vector>

#include <boost/asio/bind_allocator.hpp>
#include <boost/asio/dispatch.hpp>
#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/strand.hpp>

#include "server/common/handler_memory.hpp"

using rr::server::HandlerAllocator;
using rr::server::HandlerMemory;

namespace {
struct OwnedMemory {
    HandlerMemory* m = HandlerMemory::make();
    ~OwnedMemory() { m->release(); }
};
}  // namespace

TEST_CASE("handler memory: a block is kept and handed out again while free and large enough") {
    OwnedMemory owned;
    auto* m = owned.m;
    void* a = m->allocate(200);
    m->deallocate(a);
    CHECK(m->allocate(120) == a);  // smaller fits the kept block
    m->deallocate(a);
    CHECK(m->block_allocations() == 1);
    CHECK(m->heap_allocations() == 0);

    void* big = m->allocate(4000);  // a free slot gets a block of its own size
    CHECK(big != a);
    CHECK(m->block_allocations() == 2);
    void* again = m->allocate(100);
    CHECK(again == a);
    m->deallocate(big);
    m->deallocate(again);
}

TEST_CASE("handler memory: beyond its slots it allocates from the heap, and takes those back too") {
    OwnedMemory owned;
    auto* m = owned.m;
    std::vector<void*> held;
    for (std::size_t i = 0; i < HandlerMemory::kSlots + 3; ++i) held.push_back(m->allocate(64));
    CHECK(m->block_allocations() == HandlerMemory::kSlots);
    CHECK(m->heap_allocations() == 3);
    for (void* p : held) m->deallocate(p);
    for (std::size_t i = 0; i < HandlerMemory::kSlots; ++i) held[i] = m->allocate(64);
    CHECK(m->heap_allocations() == 3);  // the slots again, not the heap
    for (std::size_t i = 0; i < HandlerMemory::kSlots; ++i) m->deallocate(held[i]);
}

TEST_CASE("handler memory: a block given back after the owner released it") {
    HandlerMemory* m = HandlerMemory::make();
    HandlerAllocator<int> alloc(m);
    int* p = alloc.allocate(4);
    p[3] = 7;
    m->release();              // the owner is gone; the block still holds the memory
    CHECK(p[3] == 7);
    alloc.deallocate(p, 4);    // the last reference: the memory goes (ASan/valgrind check the rest)
}

TEST_CASE("handler memory: threads allocating and giving back at once") {
    OwnedMemory owned;
    auto* m = owned.m;
    std::vector<std::thread> threads;
    std::atomic<int> bad{0};
    for (int t = 0; t < 4; ++t) {
        threads.emplace_back([m, t, &bad] {
            for (int i = 0; i < 20000; ++i) {
                const std::size_t size = 32 + static_cast<std::size_t>((i * 7 + t) % 5) * 100;
                auto* p = static_cast<unsigned char*>(m->allocate(size));
                p[0] = static_cast<unsigned char>(t);
                p[size - 1] = static_cast<unsigned char>(t);
                if (p[0] != t || p[size - 1] != t) ++bad;  // another thread held the same block
                m->deallocate(p);
            }
        });
    }
    for (auto& th : threads) th.join();
    CHECK(bad == 0);
}

TEST_CASE("handler memory: strand hand-offs from another thread come from the memory, not the heap") {
    namespace asio = boost::asio;
    asio::io_context producer, consumer;
    auto guard_p = asio::make_work_guard(producer);
    auto guard_c = asio::make_work_guard(consumer);
    std::thread tp([&] { producer.run(); });
    std::thread tc([&] { consumer.run(); });
    auto strand = asio::make_strand(consumer);
    OwnedMemory owned;

    // The producer's thread hands 2,000 values one at a time to the consumer's strand, as the
    // gateway's device strand wakes each client's pump.
    constexpr int kValues = 2000;
    std::atomic<int> received{0};
    std::promise<void> done;
    std::function<void(int)> send = [&](int i) {
        asio::dispatch(strand, asio::bind_allocator(HandlerAllocator<void>(owned.m), [&, i] {
            if (received.fetch_add(1) + 1 == kValues) done.set_value();
            else asio::post(producer, [&send, i] { send(i + 1); });
        }));
    };
    asio::post(producer, [&] { send(0); });
    done.get_future().wait();
    guard_p.reset();
    guard_c.reset();
    tp.join();
    tc.join();
    CHECK(received == kValues);
    CHECK(owned.m->heap_allocations() == 0);
    CHECK(owned.m->block_allocations() >= 1);  // the strand's operation (and its invoker) were ours
    CHECK(owned.m->block_allocations() <= HandlerMemory::kSlots);
}
