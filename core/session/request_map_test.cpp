// RequestMap: outstanding requests by id; erased nodes reused, values released at once, spares bounded.
#include <catch2/catch.hpp>

#include <functional>
#include <memory>
#include <vector>

#include "core/session/request_map.hpp"

using rr::RequestMap;

TEST_CASE("request map: put, find, take and erase by id, iterated in id order") {
    RequestMap<int> m;
    CHECK(m.empty());
    m.put(7, 70);
    m.put(3, 30);
    m.put(5, 50);
    m.put(5, 55);  // replaces
    REQUIRE(m.size() == 3);
    std::vector<std::uint32_t> ids;
    for (const auto& [id, v] : m) ids.push_back(id);
    CHECK(ids == std::vector<std::uint32_t>{3, 5, 7});
    auto it = m.find(5);
    REQUIRE(it != m.end());
    CHECK(m.take(it) == 55);
    CHECK(m.find(5) == m.end());
    m.erase(7);
    m.erase(99);  // absent: nothing happens
    REQUIRE(m.size() == 1);
    CHECK(m.find(3)->second == 30);
    auto next = m.erase(m.find(3));
    CHECK(next == m.end());
    CHECK(m.empty());
}

TEST_CASE("request map: the node of an answered request carries the next one (no allocation per request)") {
    RequestMap<int> m;
    m.put(1, 10);
    const int* first = &m.find(1)->second;
    CHECK(m.take(m.find(1)) == 10);
    CHECK(m.spare_nodes() == 1);
    m.put(2, 20);
    CHECK(m.spare_nodes() == 0);
    CHECK(&m.find(2)->second == first);  // the same node, under its new id
    CHECK(m.find(1) == m.end());
    CHECK(m.find(2)->second == 20);
}

TEST_CASE("request map: an erased value is released at once, spare nodes stay bounded") {
    RequestMap<std::function<void()>> m;
    auto held = std::make_shared<int>(0);
    for (std::uint32_t id = 0; id < 20; ++id) m.put(id, [held] { ++*held; });
    CHECK(held.use_count() == 21);
    auto k = m.take(m.find(4));
    CHECK(held.use_count() == 21);  // moved out, not copied
    k();
    CHECK(*held == 1);
    k = nullptr;
    CHECK(held.use_count() == 20);
    for (auto it = m.begin(); it != m.end();) it = m.erase(it);
    CHECK(held.use_count() == 1);  // kept nodes hold nothing
    CHECK(m.spare_nodes() == RequestMap<std::function<void()>>::kSpareNodes);
    m.put(3, [held] { ++*held; });
    m.clear();
    CHECK(held.use_count() == 1);
}

TEST_CASE("request map: putting an id that is there replaces its value and keeps the spare node") {
    RequestMap<int> m;
    m.put(1, 10);
    m.put(2, 20);
    m.erase(1);
    REQUIRE(m.spare_nodes() == 1);
    m.put(2, 22);  // with a spare node at hand
    CHECK(m.size() == 1);
    CHECK(m.find(2)->second == 22);
    CHECK(m.spare_nodes() == 1);
}
