// EntryVectorPool: keeps emptied entry vectors (their storage), bounded in count and size.
#include <catch2/catch.hpp>

#include <memory>

#include "base/message/entry_vector_pool.hpp"

using namespace rr;

namespace {

std::vector<MessageEntry> entries_with_capacity(std::size_t n) {
    std::vector<MessageEntry> v;
    v.reserve(n);
    v.emplace_back();
    return v;
}

}  // namespace

TEST_CASE("entry vector pool: a given vector comes back empty with its storage") {
    EntryVectorPool pool;
    CHECK(pool.take().capacity() == 0);  // nothing kept yet: a new, empty vector
    auto v = entries_with_capacity(2);
    const MessageEntry* storage = v.data();
    pool.give(std::move(v));
    REQUIRE(pool.size() == 1);
    auto again = pool.take();
    CHECK(again.empty());
    CHECK(again.data() == storage);
    CHECK(again.capacity() >= 2);
    CHECK(pool.size() == 0);
}

TEST_CASE("entry vector pool: giving releases the entries' payloads at once") {
    EntryVectorPool pool;
    auto owner = std::make_shared<int>(7);
    std::vector<MessageEntry> v(1);
    MessageElement el;
    el.data = SharedBytes(owner, {});
    v[0].elements.push_back(std::move(el));
    CHECK(owner.use_count() == 2);
    pool.give(std::move(v));
    CHECK(owner.use_count() == 1);
    CHECK(pool.size() == 1);
}

TEST_CASE("entry vector pool: bounded in vectors kept and in their capacity") {
    EntryVectorPool pool;
    for (std::size_t i = 0; i < EntryVectorPool::kMaxVectors + 3; ++i) pool.give(entries_with_capacity(1));
    CHECK(pool.size() == EntryVectorPool::kMaxVectors);

    EntryVectorPool big;
    big.give(entries_with_capacity(EntryVectorPool::kMaxCapacity + 1));
    CHECK(big.size() == 0);
    big.give(std::vector<MessageEntry>{});  // no storage: nothing worth keeping
    CHECK(big.size() == 0);
}

TEST_CASE("entry vector pool: sent entries' element vectors come back empty with their storage, bounded") {
    EntryVectorPool pool;
    CHECK(pool.take_elements().capacity() == 0);
    auto owner = std::make_shared<int>(7);
    std::vector<MessageEntry> v(2);
    MessageElement el;
    el.data = SharedBytes(owner, {});
    v[0].elements.push_back(std::move(el));
    CHECK(owner.use_count() == 2);
    const MessageElement* storage = v[0].elements.data();
    v[1].elements.reserve(EntryVectorPool::kMaxElementCapacity + 1);  // too large to keep
    pool.give(std::move(v));
    CHECK(owner.use_count() == 1);  // the element was destroyed, only its vector's storage is kept
    REQUIRE(pool.element_vectors() == 1);
    auto elements = pool.take_elements();
    CHECK(elements.empty());
    CHECK(elements.data() == storage);
    CHECK(pool.element_vectors() == 0);

    for (std::size_t i = 0; i < EntryVectorPool::kMaxVectors + 3; ++i) {
        std::vector<MessageEntry> one(1);
        one[0].elements.reserve(1);
        pool.give(std::move(one));
    }
    CHECK(pool.element_vectors() == EntryVectorPool::kMaxVectors);
}
