// NodeDiscovery on loopback only (interfaces = {"lo"}, an ephemeral UDP port, datagrams sent by unicast
// to [::1]): nothing leaves the machine. Real multicast between network namespaces, against the official
// library, is test/interop/discovery_netns.py.
#include <catch2/catch.hpp>

#include <atomic>
#include <condition_variable>
#include <mutex>
#include <thread>

#include <boost/asio/ip/udp.hpp>

#include "core/discovery/discovery_packet.hpp"
#include "server/client/client.hpp"
#include "server/node/node.hpp"
#include "server/common/random_ids.hpp"
#include "server/discovery/node_discovery.hpp"
#include "server/transport/tcp_listener.hpp"
#include "test/support/eventually.hpp"

using namespace rr;
using namespace std::chrono_literals;
namespace asio = boost::asio;
using rr::server::discovery::DiscoveryEvent;
using rr::server::discovery::DiscoveryOptions;
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

void send_to(std::uint16_t port, const std::string& text) {
    asio::io_context io;
    asio::ip::udp::socket s(io, asio::ip::udp::v6());
    s.send_to(asio::buffer(text), asio::ip::udp::endpoint(asio::ip::make_address("::1"), port));
}

}  // namespace

TEST_CASE("discovery: announces received by UDP fill the table, hostile ones are counted") {
    client::IoThreads io(2);
    auto d = NodeDiscovery::create(io.executor(), loopback_options());
    REQUIRE(d->start());
    const auto port = d->bound_port();
    REQUIRE(port != 0);

    auto id = server::random_node_id();
    const std::string url = "rr+tcp://[::1]:1234/?nodeid=" + id.to_string() + "&service=RobotRaconteurServiceIndex";
    std::string good = std::string(discovery::kAnnounceMagic) + "\n" + id.to_braced_string() + ",test.node\n" + url +
                       "\nServiceStateNonce: abc\n";
    std::atomic<int> added{0};
    d->add_listener([&](const DiscoveryEvent& e) {
        if (e.kind == DiscoveryEvent::Kind::node_added && e.node.node_id == id) ++added;
    });
    send_to(port, good);
    REQUIRE(eventually([&] { return d->size() == 1; }));
    auto n = d->node(id);
    REQUIRE(n);
    CHECK(n->node_name == "test.node");
    CHECK(n->urls.at(0).url == url);
    CHECK(eventually([&] { return added.load() == 1; }));

    // Hostile datagrams: truncated, oversized, bad UUID, a lying URL list. None enters the table.
    send_to(port, std::string(discovery::kAnnounceMagic) + "\n" + id.to_braced_string());
    send_to(port, std::string(discovery::kAnnounceMagic) + "\n" + std::string(9000, 'A'));
    send_to(port, std::string(discovery::kAnnounceMagic) + "\n{not-a-uuid}\n" + url + "\n");
    send_to(port, std::string(discovery::kAnnounceMagic) + "\n" + server::random_node_id().to_braced_string() + "\n" +
                      url + "\n");
    REQUIRE(eventually([&] { return d->counters().rejected_total() >= 4; }));
    CHECK(d->size() == 1);
    const auto c = d->counters();
    CHECK(c.rejected[static_cast<int>(discovery::Reject::truncated)] == 1);
    CHECK(c.rejected[static_cast<int>(discovery::Reject::oversized)] == 1);
    CHECK(c.rejected[static_cast<int>(discovery::Reject::bad_node_id)] == 1);
    CHECK(c.rejected[static_cast<int>(discovery::Reject::node_id_mismatch)] == 1);
    d->stop();
}

TEST_CASE("discovery: ignored nodes (a gateway's own demo node) never enter the table") {
    client::IoThreads io(2);
    auto o = loopback_options();
    const auto demo = server::random_node_id();
    o.ignored_nodes = {demo};
    auto d = NodeDiscovery::create(io.executor(), o);
    REQUIRE(d->start());
    auto announce = [](const NodeID& id, const std::string& name) {
        return std::string(discovery::kAnnounceMagic) + "\n" + id.to_braced_string() + "," + name + "\nrr+tcp://[::1]:1234/?nodeid=" +
               id.to_string() + "&service=RobotRaconteurServiceIndex\n";
    };
    const auto other = server::random_node_id();
    send_to(d->bound_port(), announce(demo, "gw.demo"));
    send_to(d->bound_port(), announce(other, "other.node"));
    // One receiving socket takes the datagrams in the order they were sent: once the second one is in
    // the table, the first has been handled.
    REQUIRE(eventually([&] { return d->node(other).has_value(); }));
    CHECK_FALSE(d->node(demo));
    CHECK(d->size() == 1);
    CHECK(d->counters().rejected_total() == 0);  // not a hostile datagram: dropped as our own would be
    // Another source (rr+local directories) cannot add it either.
    discovery::NodeAnnouncement a{demo, "gw.demo", {"rr+local:///?nodeid=" + demo.to_string() + "&service=RobotRaconteurServiceIndex"}, "", discovery::NodeSource::local};
    CHECK(d->add_node(a) == discovery::DetectResult::ignored);
    CHECK_FALSE(d->node(demo));
    d->stop();
}

TEST_CASE("discovery: a flood of distinct NodeIDs keeps the table within its cap") {
    client::IoThreads io(2);
    auto o = loopback_options();
    o.limits.max_nodes = 32;
    auto d = NodeDiscovery::create(io.executor(), o);
    REQUIRE(d->start());
    const auto port = d->bound_port();
    asio::io_context sio;
    asio::ip::udp::socket s(sio, asio::ip::udp::v6());
    const asio::ip::udp::endpoint to(asio::ip::make_address("::1"), port);
    for (int i = 0; i < 2000; ++i) {
        auto id = server::random_node_id();
        auto text = std::string(discovery::kAnnounceMagic) + "\n" + id.to_braced_string() + "\nrr+tcp://[::1]:1/?nodeid=" +
                    id.to_string() + "&service=RobotRaconteurServiceIndex\n";
        s.send_to(asio::buffer(text), to);
        if (i % 50 == 49) std::this_thread::sleep_for(3ms);  // let the receiver keep up (UDP drops otherwise)
    }
    // UDP may drop some under load; enough arrive to overflow the table many times.
    REQUIRE(eventually([&] { return d->counters().announces >= 300; }));
    // Datagrams may still be arriving: every accepted one is a new node that evicts one, so the counts
    // agree in any one snapshot (taken under the table's lock), whenever it is taken.
    const auto c = d->counters();
    CHECK(c.evictions == c.announces - 32);
    CHECK(d->size() == 32);
    d->stop();
}

TEST_CASE("discovery: ServiceInfo2 from a node's RobotRaconteurServiceIndex") {
    auto node = server::Node::create({});
    auto tcp_port = listen_tcp(node, "::1", 0);
    REQUIRE(tcp_port);
    client::IoThreads io(2);
    auto d = NodeDiscovery::create(io.executor(), loopback_options());
    REQUIRE(d->start());
    std::mutex m;
    std::condition_variable cv;
    std::vector<server::discovery::ServiceInfo2> services;
    d->add_listener([&](const DiscoveryEvent& e) {
        if (e.kind != DiscoveryEvent::Kind::services_updated || !e.node.services) return;
        std::lock_guard lock(m);
        services = *e.node.services;
        cv.notify_all();
    });
    d->want_services(true);
    const auto id = node->node_id();
    send_to(d->bound_port(), std::string(discovery::kAnnounceMagic) + "\n" + id.to_braced_string() + "\nrr+tcp://[::1]:" +
                                 std::to_string(*tcp_port) + "/?nodeid=" + id.to_string() +
                                 "&service=RobotRaconteurServiceIndex\nServiceStateNonce: n1\n");
    std::unique_lock lock(m);
    REQUIRE(cv.wait_for(lock, 30s, [&] { return !services.empty(); }));  // a bound on a hang
    CHECK(services.at(0).name == "RobotRaconteurServiceIndex");
    CHECK(services.at(0).root_object_type == "RobotRaconteurServiceIndex.ServiceIndex");
    CHECK(services.at(0).node_id == id);
    REQUIRE(services.at(0).connection_urls.size() == 1);
    CHECK(services.at(0).connection_urls[0].find("service=RobotRaconteurServiceIndex") != std::string::npos);
    lock.unlock();
    d->stop();
    node->shutdown();
}

TEST_CASE("discovery: link-local URLs get the interface they were heard on") {
    client::IoThreads io(1);
    auto d = NodeDiscovery::create(io.executor(), loopback_options());
    // Unknown host: every local link-local interface (here only lo, which has none): the URL as it is.
    const std::string url = "rr+tcp://[fe80::1]:5/?nodeid=d835c41d-339c-47a8-84db-f00a8fefd2fa&service=x";
    CHECK(d->connectable_urls(url) == std::vector<std::string>{url});
    const std::string v4 = "rr+tcp://10.0.0.1:5/?service=x";
    CHECK(d->connectable_urls(v4) == std::vector<std::string>{v4});
}
