// ConversionBudget: a JSON socket's allowance of pipe packets waiting for their JSON.
#include <catch2/catch.hpp>

#include "server/gateway/conversion_budget.hpp"

using rr::server::gateway::ConversionBudget;

TEST_CASE("conversion budget: bounded by count and by bytes, one large packet alone still goes") {
    ConversionBudget b(3, 1000);
    CHECK(b.try_acquire(10));
    CHECK(b.try_acquire(10));
    CHECK(b.try_acquire(10));
    CHECK_FALSE(b.try_acquire(1));  // count
    CHECK(b.waiting() == 3);
    b.release(10);
    CHECK_FALSE(b.try_acquire(990));  // 20 + 990 > 1000
    CHECK(b.try_acquire(980));        // exactly 1000
    b.release(10);
    b.release(10);
    b.release(980);
    CHECK(b.waiting() == 0);
    CHECK(b.try_acquire(5000));  // alone: a frame larger than the budget is not refused outright
    CHECK_FALSE(b.try_acquire(1));
    b.release(5000);
    CHECK(b.try_acquire(1));
}

TEST_CASE("conversion budget: payload_bytes counts nested elements") {
    rr::MessageElement leaf;
    leaf.data = rr::SharedBytes::adopt(std::vector<std::byte>(100));
    rr::MessageElement s;
    s.elements = {leaf, leaf};
    s.elements[1].elements = {leaf};
    CHECK(rr::server::gateway::payload_bytes(s) == 300);
}
