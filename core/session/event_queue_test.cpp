// EventQueue: the sessions' event FIFO (order kept across interleaved pushes and pops, storage reused).
#include <catch2/catch.hpp>

#include <string>

#include "core/session/event_queue.hpp"

using rr::EventQueue;

TEST_CASE("event queue: first in, first out, also while events are added between takes") {
    EventQueue<std::string> q;
    CHECK(q.empty());
    CHECK_FALSE(q.pop());
    q.push_back("a");
    q.emplace_back("b");
    CHECK(q.size() == 2);
    CHECK(*q.pop() == "a");
    q.push_back("c");
    CHECK(*q.pop() == "b");
    CHECK(*q.pop() == "c");
    CHECK(q.empty());
    CHECK_FALSE(q.pop());
}

TEST_CASE("event queue: a host that never drains it completely still gets every event in order") {
    EventQueue<int> q;
    int next_in = 0, next_out = 0;
    q.push_back(next_in++);
    for (int round = 0; round < 1000; ++round) {
        q.push_back(next_in++);
        q.push_back(next_in++);
        for (int k = 0; k < 2; ++k) {
            auto v = q.pop();
            REQUIRE(v);
            REQUIRE(*v == next_out++);
        }
        REQUIRE(q.size() == 1);  // one always left behind
    }
    CHECK(*q.pop() == next_out);
    CHECK(q.empty());
}
