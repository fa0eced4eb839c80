// RecordQueue (record_queue.hpp): the live path's side of a recording. It keeps the shared entry itself
// (the same object and bytes, one more reference), counts drops exactly when its byte budget is full,
// reuses its storage from batch to batch, and wakes the writer only when half full or closed.
#include <catch2/catch.hpp>

#include <algorithm>
#include <chrono>
#include <thread>

#include "server/record/record_queue.hpp"

using rr::server::record::RecordQueue;
using namespace std::chrono_literals;

namespace {

rr::server::gateway::SharedEntryPtr entry_of_bytes(std::size_t n) {
    rr::MessageEntry e;
    e.entry_type = rr::MessageEntryType::WirePacket;
    e.member_name = "Frames";
    rr::MessageElement el;
    el.name = "value";
    el.data = rr::SharedBytes::adopt(std::vector<std::byte>(n));
    e.elements.push_back(std::move(el));
    return std::make_shared<const rr::server::gateway::SharedEntry>(std::move(e));
}

}  // namespace

TEST_CASE("record queue: holds the live path's entry, not a copy") {
    RecordQueue q(1 << 20);
    auto entry = entry_of_bytes(921600);
    const auto* bytes = entry->entry().elements[0].data.data();
    REQUIRE(q.offer(3, 42, entry) == RecordQueue::Offered::queued);
    CHECK(entry.use_count() == 2);  // ours and the queue's
    CHECK(q.queued_bytes() == RecordQueue::weight(entry->entry()));
    std::vector<RecordQueue::Item> batch;
    CHECK_FALSE(q.take(batch, 0ms));
    REQUIRE(batch.size() == 1);
    CHECK(batch[0].entry.get() == entry.get());
    CHECK(batch[0].entry->entry().elements[0].data.data() == bytes);
    CHECK(batch[0].member == 3);
    CHECK(batch[0].log_ns == 42);
    CHECK(q.queued_bytes() == RecordQueue::weight(entry->entry()));  // the writer holds it
    batch.clear();
    CHECK(entry.use_count() == 1);
    q.take(batch, 0ms);  // the writer is back for more: its last batch is done
    CHECK(q.queued_bytes() == 0);
}

TEST_CASE("record queue: drops are counted exactly when the budget is full") {
    auto entry = entry_of_bytes(1000);
    const std::size_t w = RecordQueue::weight(entry->entry());
    CHECK(w == 128 + 64 + 1000);
    RecordQueue q(4096);  // three fit (3,576 bytes), a fourth would not
    for (int i = 0; i < 3; ++i) CHECK(q.offer(0, 0, entry) == RecordQueue::Offered::queued);
    CHECK(q.offer(0, 0, entry) == RecordQueue::Offered::dropped);
    CHECK(q.offer(0, 0, entry) == RecordQueue::Offered::dropped);
    CHECK(q.drops() == 2);
    CHECK(q.queued_bytes() == 3 * w);
    CHECK(entry.use_count() == 4);  // a dropped entry is not kept
    std::vector<RecordQueue::Item> batch;
    q.take(batch, 0ms);
    CHECK(batch.size() == 3);
    // issue 52: while the writer holds the batch it still counts, so the queue and the batch together
    // stay within the budget (they held twice the budget before)
    CHECK(q.offer(0, 0, entry) == RecordQueue::Offered::dropped);
    CHECK(q.queued_bytes() == 3 * w);
    CHECK(q.drops() == 3);
    batch.clear();
    q.take(batch, 0ms);  // written: room again
    CHECK(q.offer(0, 0, entry) == RecordQueue::Offered::queued);
    CHECK(q.drops() == 3);
}

TEST_CASE("record queue: the queue and the writer's batch never weigh more than the budget") {
    auto entry = entry_of_bytes(1000);
    const std::size_t w = RecordQueue::weight(entry->entry());
    RecordQueue q(100 * w);
    std::vector<RecordQueue::Item> batch;
    std::size_t held_max = 0;
    // A writer slower than the live path: each round the live path offers 60 entries while the writer
    // holds its batch.
    for (int round = 0; round < 20; ++round) {
        for (int i = 0; i < 60; ++i) q.offer(0, 0, entry);
        std::size_t in_hand = 0;
        for (const auto& item : batch) in_hand += item.bytes;
        held_max = std::max(held_max, q.queued_bytes());
        CHECK(q.queued_bytes() <= 100 * w);
        CHECK(in_hand <= q.queued_bytes());
        batch.clear();
        q.take(batch, 0ms);
    }
    CHECK(held_max == 100 * w);
    CHECK(q.drops() > 0);
}

TEST_CASE("record queue: storage is reused from batch to batch") {
    RecordQueue q(1 << 20);
    auto entry = entry_of_bytes(10);
    std::vector<RecordQueue::Item> batch;
    for (int i = 0; i < 10; ++i) q.offer(0, 0, entry);
    q.take(batch, 0ms);
    const auto* storage = batch.data();
    batch.clear();
    q.take(batch, 0ms);  // hands the emptied storage back to the queue
    CHECK(batch.empty());
    for (int i = 0; i < 10; ++i) q.offer(0, 0, entry);
    batch.clear();
    q.take(batch, 0ms);
    REQUIRE(batch.size() == 10);
    CHECK(batch.data() == storage);  // the same buffer: no allocation for these ten
}

TEST_CASE("record queue: closed, it takes nothing more and hands over the rest") {
    RecordQueue q(1 << 20);
    auto entry = entry_of_bytes(10);
    q.offer(1, 0, entry);
    q.close();
    CHECK(q.offer(2, 0, entry) == RecordQueue::Offered::closed);
    std::vector<RecordQueue::Item> batch;
    const auto t0 = std::chrono::steady_clock::now();
    CHECK(q.take(batch, 10s));  // closed: no wait
    CHECK(std::chrono::steady_clock::now() - t0 < 5s);
    REQUIRE(batch.size() == 1);
    CHECK(batch[0].member == 1);

    RecordQueue failed(1 << 20);
    failed.offer(1, 0, entry);
    failed.close_and_clear();
    batch.clear();
    CHECK(failed.take(batch, 0ms));
    CHECK(batch.empty());
    CHECK(entry.use_count() == 1);
}

TEST_CASE("record queue: the writer is woken at half the budget, not per value") {
    auto entry = entry_of_bytes(1000);  // 1,192 bytes each
    RecordQueue q(12000);               // half: 6,000 bytes, crossed by the sixth entry
    std::vector<RecordQueue::Item> batch;
    // One value waiting: the writer sleeps its period out. (Offered before the take: a thread offering
    // "during" the wait could, on a loaded machine, offer after the period and leave the batch empty.)
    q.offer(0, 0, entry);
    auto t0 = std::chrono::steady_clock::now();
    q.take(batch, 400ms);
    CHECK(std::chrono::steady_clock::now() - t0 >= 390ms);
    CHECK(batch.size() == 1);
    batch.clear();
    // Six values: woken early (whether they come before the take or during its wait).
    std::thread six([&] {
        std::this_thread::sleep_for(20ms);
        for (int i = 0; i < 6; ++i) q.offer(0, 0, entry);
    });
    t0 = std::chrono::steady_clock::now();
    q.take(batch, 30s);
    six.join();
    CHECK(std::chrono::steady_clock::now() - t0 < 20s);
    CHECK(batch.size() == 6);  // the wake comes with the sixth
}

TEST_CASE("record queue: a wire's value that arrived before the newest one offered is stale, not a drop") {
    RecordQueue q(1 << 20);
    const auto older = entry_of_bytes(8);  // the wire's newest when the recording joined it
    const auto newer = entry_of_bytes(8);  // came from the device after it, fanned out first
    REQUIRE(newer->arrival() > older->arrival());
    CHECK(q.offer_newest(0, 1, newer) == RecordQueue::Offered::queued);
    CHECK(q.offer_newest(0, 2, older) == RecordQueue::Offered::stale);
    CHECK(q.offer_newest(0, 3, newer) == RecordQueue::Offered::stale);  // the same one again
    CHECK(q.offer_newest(1, 4, older) == RecordQueue::Offered::queued);  // another member's order
    CHECK(q.offer(0, 5, older) == RecordQueue::Offered::queued);          // events and pipes keep every value
    CHECK(q.drops() == 0);
    std::vector<RecordQueue::Item> batch;
    q.take(batch, 0ms);
    REQUIRE(batch.size() == 3);
    CHECK(batch[0].entry == newer);
    CHECK(batch[1].member == 1);
    CHECK(batch[2].log_ns == 5);
}
