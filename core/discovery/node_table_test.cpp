#include <catch2/catch.hpp>

#include <cstdio>

#include "core/discovery/node_table.hpp"

using namespace rr;
using namespace rr::discovery;
using namespace std::chrono_literals;

namespace {

NodeID make_id(unsigned n) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%08x-0000-4000-8000-000000000001", n + 1);
    return *NodeID::parse(buf);
}

std::string url_for(const NodeID& id, const std::string& host = "[fe80::1]", int port = 4242) {
    return "rr+tcp://" + host + ":" + std::to_string(port) + "/?nodeid=" + id.to_string() +
           "&service=RobotRaconteurServiceIndex";
}

NodeAnnouncement ann(const NodeID& id, std::string url, std::string name = "n", std::string nonce = "") {
    NodeAnnouncement a;
    a.node_id = id;
    a.node_name = std::move(name);
    a.urls = {std::move(url)};
    a.service_state_nonce = std::move(nonce);
    return a;
}

const MonoTime t0 = MonoTime{} + 1000s;

}  // namespace

TEST_CASE("discovery table: nodes appear, refresh and expire 60 s after their last announce") {
    NodeTable t;
    auto id = make_id(1);
    CHECK(t.node_detected(ann(id, url_for(id), "a"), t0) == DetectResult::added);
    CHECK(t.node_detected(ann(id, url_for(id), "a"), t0 + 30s) == DetectResult::refreshed);
    CHECK(t.node_detected(ann(id, url_for(id, "[fe80::2]"), "a"), t0 + 40s) == DetectResult::updated);
    REQUIRE(t.find(id));
    CHECK(t.find(id)->urls.size() == 2);
    CHECK(t.find_by_name("a").size() == 1);
    CHECK(t.next_deadline() == t0 + 90s);
    CHECK(t.oldest_announce() == t0 + 30s);

    CHECK(t.expire(t0 + 89s).empty());
    CHECK(t.find(id)->urls.size() == 2);
    CHECK(t.expire(t0 + 90s).empty());  // the first URL is gone, the second (t0+40s) lives
    CHECK(t.find(id)->urls.size() == 1);
    auto lost = t.expire(t0 + 100s);
    REQUIRE(lost.size() == 1);
    CHECK(lost[0].node_id == id);
    CHECK(t.size() == 0);
    CHECK(t.counters().expired == 1);
    CHECK_FALSE(t.next_deadline());
}

TEST_CASE("discovery table: URLs that lie about the node or do not parse are dropped") {
    NodeTable t;
    auto id = make_id(1), other = make_id(2);
    NodeAnnouncement a = ann(id, url_for(other));
    CHECK(t.node_detected(a, t0) == DetectResult::ignored);
    a.urls = {"rr+tcp://[fe80::1", url_for(id), url_for(id), std::string(300, 'x')};
    CHECK(t.node_detected(a, t0) == DetectResult::added);
    CHECK(t.find(id)->urls.size() == 1);
    CHECK(t.counters().urls_rejected == 4);
    CHECK(t.node_detected(ann(NodeID(), url_for(NodeID())), t0) == DetectResult::ignored);
}

TEST_CASE("discovery table: a flood of distinct NodeIDs stays within the cap, oldest evicted") {
    NodeTableLimits limits;
    limits.max_nodes = 64;
    limits.max_urls_per_node = 4;
    NodeTable t(limits);
    auto keeper = make_id(0);
    t.node_detected(ann(keeper, url_for(keeper)), t0);
    for (unsigned i = 1; i <= 10000; ++i) {
        auto id = make_id(i);
        t.node_detected(ann(id, url_for(id)), t0 + std::chrono::milliseconds(i));
        if (i % 50 == 0) t.node_detected(ann(keeper, url_for(keeper)), t0 + std::chrono::milliseconds(i));
        REQUIRE(t.size() <= 64);
    }
    CHECK(t.size() == 64);
    CHECK(t.counters().evictions == 10001 - 64);
    CHECK(t.find(keeper));            // heard from recently, never the oldest
    CHECK_FALSE(t.find(make_id(1)));  // the oldest went first
    CHECK(t.find(make_id(10000)));
    CHECK(t.take_evicted().size() == 64);  // handed out (at most max_nodes kept between calls)
    CHECK(t.take_evicted().empty());

    // Many URLs for one node: at most 4 kept, the oldest replaced.
    auto id = make_id(20000);
    for (int p = 1; p <= 20; ++p) t.node_detected(ann(id, url_for(id, "[fe80::1]", p)), t0 + 20s + std::chrono::seconds(p));
    CHECK(t.find(id)->urls.size() == 4);
    CHECK(t.find(id)->urls.back().url == url_for(id, "[fe80::1]", 20));
    CHECK(t.counters().url_evictions == 16);
}

TEST_CASE("discovery table: service interrogation follows the nonce") {
    NodeTable t;
    auto id = make_id(1);
    t.node_detected(ann(id, url_for(id), "a", "N1"), t0, 0);
    CHECK(t.take_due_updates(t0 + 10s).empty());  // nobody wants services yet

    t.set_want_services(true, t0 + 10s);
    CHECK(t.take_due_updates(t0 + 10s).empty());
    auto due = t.take_due_updates(t0 + 10s + 600ms);
    REQUIRE(due.size() == 1);
    CHECK(t.take_due_updates(t0 + 20s).empty());  // running

    ServiceInfo2 s;
    s.name = "svc";
    s.root_object_type = "x.Y";
    CHECK(t.services_updated(id, "N1", {s}, t0 + 11s));
    REQUIRE(t.find(id)->services);
    CHECK(t.find(id)->services->at(0).node_id == id);
    CHECK(t.find(id)->services->at(0).node_name == "a");

    // Same nonce again: nothing to do. A new nonce: due within 100-600 ms.
    t.node_detected(ann(id, url_for(id), "a", "N1"), t0 + 20s, 0);
    CHECK(t.take_due_updates(t0 + 25s).empty());
    t.node_detected(ann(id, url_for(id), "a", "N2"), t0 + 30s, 0);
    CHECK(t.take_due_updates(t0 + 30s + 99ms).empty());
    CHECK(t.take_due_updates(t0 + 30s + 100ms).size() == 1);

    // Failures back off progressively (CORE: 100-600 ms, then 2-2.5 s after 4 tries, …).
    MonoTime now = t0 + 31s;
    for (int i = 0; i < 5; ++i) {
        t.services_failed(id, "refused", now, 0);
        auto next = t.next_deadline();
        REQUIRE(next);
        now = *next;
        REQUIRE(t.take_due_updates(now).size() == 1);
    }
    t.services_failed(id, "refused", now, 0);
    CHECK(t.take_due_updates(now + 1999ms).empty());
    CHECK(t.take_due_updates(now + 2000ms).size() == 1);
    CHECK(t.find(id)->last_error == "refused");
}

TEST_CASE("discovery table: a nonce change during interrogation asks again") {
    NodeTable t;
    auto id = make_id(1);
    t.set_want_services(true, t0);
    t.node_detected(ann(id, url_for(id), "a", "N1"), t0, 0);
    REQUIRE(t.take_due_updates(t0 + 1s).size() == 1);
    t.node_detected(ann(id, url_for(id), "a", "N2"), t0 + 1100ms, 0);
    t.services_updated(id, "N1", {}, t0 + 1200ms);
    CHECK(t.take_due_updates(t0 + 2s).size() == 1);
}

TEST_CASE("discovery table: other sources feed the same table") {
    NodeTable t;
    auto id = make_id(7);
    NodeAnnouncement a;
    a.node_id = id;
    a.node_name = "local.node";
    a.source = NodeSource::local;
    a.urls = {"rr+local:///?nodeid=" + id.to_string() + "&service=RobotRaconteurServiceIndex"};
    CHECK(t.node_detected(a, t0) == DetectResult::added);
    CHECK(t.find(id)->source == NodeSource::local);
    CHECK(node_source_name(t.find(id)->source) == "local");
    CHECK(t.remove(id));
    CHECK(t.size() == 0);
}

TEST_CASE("discovery table: a source removes only its own URLs of a node") {
    NodeTable t;
    auto id = make_id(8);
    const std::string local = "rr+local:///?nodeid=" + id.to_string() + "&service=RobotRaconteurServiceIndex";
    NodeAnnouncement a = ann(id, url_for(id));
    CHECK(t.node_detected(a, t0) == DetectResult::added);
    NodeAnnouncement l = ann(id, local);
    l.source = NodeSource::local;
    CHECK(t.node_detected(l, t0 + 1s) == DetectResult::updated);
    REQUIRE(t.find(id)->urls.size() == 2);
    std::optional<NodeEntry> lost;
    CHECK_FALSE(t.remove_urls(make_id(9), {local}, lost));
    CHECK_FALSE(t.remove_urls(id, {"rr+local:///?nodeid=other"}, lost));
    CHECK(t.remove_urls(id, {local}, lost));
    CHECK_FALSE(lost);
    REQUIRE(t.find(id));
    CHECK(t.find(id)->urls.size() == 1);
    CHECK(t.find(id)->urls[0].url == url_for(id));
    CHECK(t.remove_urls(id, {url_for(id)}, lost));
    REQUIRE(lost);
    CHECK(lost->node_id == id);
    CHECK(t.size() == 0);
}

TEST_CASE("discovery table: ServiceInfo2 from a GetLocalNodeServices value") {
    auto id = make_id(3);
    Structure s{"RobotRaconteurServiceIndex.ServiceInfo", {}};
    s.set("Name", Value("robot"));
    s.set("RootObjectType", Value("ex.Robot"));
    MapInt32 impl;
    impl.entries.emplace_back(1, Value("ex.Base2"));
    impl.entries.emplace_back(0, Value("ex.Base"));
    s.set("RootObjectImplements", Value(impl));
    MapInt32 urls;
    urls.entries.emplace_back(1, Value("rr+tcp://[fe80::1]:1/?nodeid=" + id.to_string() + "&service=robot"));
    s.set("ConnectionURL", Value(urls));
    MapString attrs;
    attrs.entries.emplace_back("tags", Value("a,b"));
    s.set("Attributes", Value(attrs));
    MapInt32 ret;
    ret.entries.emplace_back(0, Value(s));
    auto infos = service_infos_from_value(Value(ret), id, "n");
    REQUIRE(infos);
    REQUIRE(infos->size() == 1);
    CHECK(infos->at(0).name == "robot");
    CHECK(infos->at(0).root_object_implements == std::vector<std::string>{"ex.Base", "ex.Base2"});
    CHECK(infos->at(0).connection_urls.size() == 1);
    CHECK(infos->at(0).attributes.find("tags"));

    CHECK_FALSE(service_infos_from_value(Value("nope"), id, "n"));
    Structure bad = s;
    bad.set("Name", Value::scalar<std::int32_t>(3));
    MapInt32 ret2;
    ret2.entries.emplace_back(0, Value(bad));
    CHECK_FALSE(service_infos_from_value(Value(ret2), id, "n"));
    ServiceInfoLimits small;
    small.max_services = 0;
    CHECK(service_infos_from_value(Value(ret), id, "n", small).error().type == MessageErrorType::OutOfRange);
}

TEST_CASE("discovery table: nodes whose service index answered outlive a flood") {
    NodeTableLimits limits;
    limits.max_nodes = 16;
    NodeTable t(limits);
    t.set_want_services(true, t0);
    auto real = make_id(0);
    t.node_detected(ann(real, url_for(real), "real", "N"), t0);
    REQUIRE(t.take_due_updates(t0 + 1s).size() == 1);
    REQUIRE(t.services_updated(real, "N", {}, t0 + 1s));
    for (unsigned i = 1; i <= 500; ++i) {
        auto id = make_id(i);
        t.node_detected(ann(id, url_for(id)), t0 + 2s + std::chrono::milliseconds(i));
    }
    CHECK(t.size() == 16);
    CHECK(t.find(real));  // the oldest, but verified
    CHECK(t.counters().evictions == 500 - 15);
}
