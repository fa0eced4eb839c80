// The rr+local source of the discovery table (discovery_sources.hpp) and the node's one
// ServiceStateNonce, in temporary node directories; UDP on loopback only.
#include <catch2/catch.hpp>

#include <algorithm>
#include <mutex>
#include <thread>

#include "server/client/client.hpp"
#include "server/common/random_ids.hpp"
#include "server/node/node.hpp"
#include "server/service/test_raw_service.hpp"
#include "server/discovery/discovery_sources.hpp"
#include "server/transport/local/local_connector.hpp"
#include "server/transport/local/local_listener.hpp"
#include "server/transport/local/local_test_support.hpp"
#include "test/support/eventually.hpp"

using namespace rr;
using namespace std::chrono_literals;
using rr::server::discovery::DiscoveryEvent;
using rr::server::discovery::DiscoveryOptions;
using rr::server::discovery::LocalDiscoverySource;
using rr::server::discovery::LocalSourceOptions;
using rr::server::discovery::NodeDiscovery;

namespace {

using rr::testing::eventually;

DiscoveryOptions loopback_options() {
    DiscoveryOptions o;
    o.port = 0;
    o.interfaces = {"lo"};
    o.listen = true;
    return o;
}

struct Served {
    std::shared_ptr<server::Node> node;
    std::shared_ptr<server::local::LocalListener> listener;
};

Served serve(const server::local::NodeDirectories& dirs, const std::string& name) {
    auto r = server::local::reserve_node_name(dirs, name);
    REQUIRE(r);
    server::NodeOptions o;
    o.node_id = r->node_id;
    o.node_name = name;
    o.threads = 2;
    auto node = server::Node::create(o);
    REQUIRE(node->register_service(std::make_shared<server::testing::RawTestService>()));
    server::local::LocalListenOptions lo;
    lo.dirs = dirs;
    auto l = server::local::listen_local(node, lo, std::move(*r));
    REQUIRE(l);
    return {node, *l};
}

}  // namespace

TEST_CASE("discovery sources: rr+local nodes enter the table, are interrogated over rr+local, and leave") {
    server::local::testing::TempNodeDirs tmp;
    client::IoThreads io(2);
    // Interrogations over rr+local search the test's node directories, not this process's.
    server::TransportRegistry transports;
    transports.add("rr+local", std::make_shared<server::local::LocalConnector>([dirs = tmp.dirs] { return dirs; }));
    auto dopts = loopback_options();
    dopts.transports = &transports;
    auto d = NodeDiscovery::create(io.executor(), dopts);
    REQUIRE(d->start());
    std::mutex m;
    std::vector<DiscoveryEvent> events;
    d->add_listener([&](const DiscoveryEvent& e) {
        std::lock_guard lock(m);
        events.push_back(e);
    });
    d->want_services(true);
    auto count = [&](DiscoveryEvent::Kind k, const NodeID& id) {
        std::lock_guard lock(m);
        return std::count_if(events.begin(), events.end(), [&](const DiscoveryEvent& e) { return e.kind == k && e.node.node_id == id; });
    };

    LocalSourceOptions so;
    so.dirs = tmp.dirs;
    so.watch.scan.include_own_process = true;  // the served node lives in this test process
    auto source = LocalDiscoverySource::start(io.executor(), d, so);
    auto s = serve(tmp.dirs, server::local::testing::unique_node_name("src.local"));
    const auto id = s.node->node_id();
    const std::string index_url = "rr+local:///?nodeid=" + id.to_string() + "&service=RobotRaconteurServiceIndex";

    REQUIRE(eventually([&] { return d->node(id).has_value(); }));
    auto n = d->node(id);
    CHECK(n->node_name == s.node->node_name());
    CHECK(n->source == rr::discovery::NodeSource::local);
    REQUIRE(n->urls.size() == 1);
    CHECK(n->urls[0].url == index_url);
    CHECK(n->service_state_nonce == s.node->service_state_nonce());

    // Its services, read over rr+local.
    REQUIRE(eventually([&] {
        auto x = d->node(id);
        return x && x->services && !x->services->empty();
    }));
    n = d->node(id);
    auto svc = std::find_if(n->services->begin(), n->services->end(), [](const auto& x) { return x.name == "svc"; });
    REQUIRE(svc != n->services->end());
    CHECK(svc->root_object_type == "example.rawtest.Obj");
    CHECK(svc->connection_urls == std::vector<std::string>{"rr+local:///?nodeid=" + id.to_string() + "&service=svc"});

    // A change of services: the entries carry the node's new nonce, the table follows and asks again.
    const auto old_nonce = n->service_state_nonce;
    s.node->unregister_service("svc");
    CHECK(s.listener->service_state_nonce() == s.node->service_state_nonce());
    REQUIRE(eventually([&] {
        auto x = d->node(id);
        return x && x->services_nonce == s.node->service_state_nonce() && x->services_nonce != old_nonce;
    }));
    n = d->node(id);
    CHECK(std::none_of(n->services->begin(), n->services->end(), [](const auto& x) { return x.name == "svc"; }));

    // Also known over the network: the node stays when its rr+local entry goes, only that URL leaves.
    const std::string tcp_url = "rr+tcp://[::1]:9/?nodeid=" + id.to_string() + "&service=RobotRaconteurServiceIndex";
    d->add_node({id, s.node->node_name(), {tcp_url}, {}, rr::discovery::NodeSource::udp});
    REQUIRE(d->node(id)->urls.size() == 2);
    s.listener->close();
    REQUIRE(eventually([&] { return d->node(id) && d->node(id)->urls.size() == 1; }));
    CHECK(d->node(id)->urls[0].url == tcp_url);
    CHECK(count(DiscoveryEvent::Kind::node_updated, id) >= 1);
    CHECK(count(DiscoveryEvent::Kind::node_lost, id) == 0);
    d->remove_urls(id, {tcp_url});
    CHECK_FALSE(d->node(id));
    CHECK(eventually([&] { return count(DiscoveryEvent::Kind::node_lost, id) == 1; }));

    // A node only rr+local knew is lost when its server stops.
    auto s2 = serve(tmp.dirs, server::local::testing::unique_node_name("src.local2"));
    const auto id2 = s2.node->node_id();
    REQUIRE(eventually([&] { return d->node(id2).has_value(); }));
    s2.listener->close();
    CHECK(eventually([&] { return count(DiscoveryEvent::Kind::node_lost, id2) == 1; }));
    CHECK_FALSE(d->node(id2));

    source->stop();
    d->stop(6s);
    s.node->shutdown();
    s2.node->shutdown();
}

TEST_CASE("discovery: the announced ServiceStateNonce is the node's when a provider is given") {
    client::IoThreads io(1);
    auto node = server::Node::create({});
    auto o = loopback_options();
    std::weak_ptr<server::Node> weak = node;
    o.service_state_nonce = [weak] { return weak.lock()->service_state_nonce(); };
    auto d = NodeDiscovery::create(io.executor(), o);
    CHECK(d->service_state_nonce() == node->service_state_nonce());
    CHECK(node->service_state_nonce().size() == 16);
    const auto before = node->service_state_nonce();
    REQUIRE(node->register_service(std::make_shared<server::testing::RawTestService>()));
    CHECK(node->service_state_nonce() != before);
    d->services_changed();
    CHECK(d->service_state_nonce() == node->service_state_nonce());
    // Without a provider the discovery keeps its own and renews it.
    auto own = NodeDiscovery::create(io.executor(), loopback_options());
    const auto n1 = own->service_state_nonce();
    own->services_changed();
    CHECK(own->service_state_nonce() != n1);
    CHECK(own->service_state_nonce().size() == 16);
    node->shutdown();
}
