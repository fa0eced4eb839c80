// EventQueue: the sessions' event FIFO (order kept across interleaved pushes and pops, storage reused).
#include <catch2/catch.hpp>

#include <string>
#include <vector>

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

TEST_CASE("event queue: take_all hands over every event in order, after pops and with events added meanwhile") {
    EventQueue<std::string> q;
    std::vector<std::string> batch{"stale"};
    q.take_all(batch);
    CHECK(batch.empty());  // the old batch is destroyed even when nothing is queued

    q.push_back("a");
    q.push_back("b");
    q.push_back("c");
    CHECK(*q.pop() == "a");
    q.take_all(batch);  // after a pop: the rest, in order
    CHECK(batch == std::vector<std::string>{"b", "c"});
    CHECK(q.empty());

    q.push_back("d");  // queued while the batch is handled
    q.emplace_back("e");
    q.take_all(batch);
    CHECK(batch == std::vector<std::string>{"d", "e"});
    q.push_back("f");
    CHECK(*q.pop() == "f");
    CHECK_FALSE(q.pop());
}

TEST_CASE("event queue: pop_back removes only the newest event") {
    EventQueue<int> q;
    q.push_back(1);
    q.emplace_back(2) = 3;  // emplace_back returns the new event, to fill in place
    q.push_back(4);
    q.pop_back();
    CHECK(q.size() == 2);
    CHECK(*q.pop() == 1);
    CHECK(*q.pop() == 3);
    CHECK(q.empty());
}
