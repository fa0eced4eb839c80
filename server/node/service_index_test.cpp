// The node's built-in RobotRaconteurServiceIndex over loopback TCP, read with our typed client.
// (The official Python client against it: test/cli/service_index_official.py.)
#include <catch2/catch.hpp>

#include <atomic>
#include <thread>

#include "core/value/pack_value.hpp"
#include "robdef/service_definition_set.hpp"
#include "server/client/client.hpp"
#include "server/node/node.hpp"
#include "server/service/test_raw_service.hpp"
#include "server/transport/tcp_listener.hpp"
#include "test/support/eventually.hpp"

using namespace rr;
using namespace std::chrono_literals;
using rr::client::Client;

namespace {

// The raw test service with attributes: two array-valued ones (kept by the index) and a list (dropped).
class AttributedService : public server::testing::RawTestService {
public:
    MessageElement attributes() const override {
        robdef::TypeDefinition t;
        t.base = DataTypes::varvalue_t;
        t.container = robdef::ContainerKind::map_string;
        MapString m;
        m.entries.emplace_back("location", Value(std::string("lab 2")));
        m.entries.emplace_back("gain", Value::scalar(2.5));
        m.entries.emplace_back("tags", Value(List{{Value(std::string("a"))}}));
        robdef::ServiceDefinitionSet lookup;
        auto e = pack_value(Value(std::move(m)), t, "attributes", lookup, "");
        return e ? *e : RawTestService::attributes();  // (called on server threads: no REQUIRE here)
    }
};

const Structure& info_at(const MapInt32& m, std::int32_t key) {
    const Value* v = m.find(key);
    REQUIRE(v);
    const auto* s = v->get_if<Structure>();
    REQUIRE(s);
    return *s;
}

std::string str_field(const Structure& s, std::string_view name) {
    const Value* v = s.find(name);
    REQUIRE(v);
    const auto* str = v->get_if<std::string>();
    REQUIRE(str);
    return *str;
}

}  // namespace

TEST_CASE("node: RobotRaconteurServiceIndex lists the registered services with their URLs") {
    auto node = server::Node::create(server::NodeOptions{NodeID(), "indextest.node", 2, {}, 0, 5000ms});
    REQUIRE(node->register_service(std::make_shared<AttributedService>()));
    auto port = listen_tcp(node, "127.0.0.1", 0);
    REQUIRE(port);
    const std::string base = "rr+tcp://127.0.0.1:" + std::to_string(*port) + "/";
    rr::client::IoThreads io{1};

    auto c = Client::connect(io.executor(), base + "?service=RobotRaconteurServiceIndex");
    REQUIRE(c);
    auto root = (*c)->root();
    CHECK(root.type() == "RobotRaconteurServiceIndex.ServiceIndex");
    CHECK(node->service_names() == std::vector<std::string>{"svc"});  // the index is built in, not registered

    auto r = root.call("GetLocalNodeServices");
    REQUIRE(r);
    const auto* map = r->get_if<MapInt32>();
    REQUIRE(map);
    REQUIRE(map->entries.size() == 2);
    CHECK(str_field(info_at(*map, 0), "Name") == "RobotRaconteurServiceIndex");
    CHECK(str_field(info_at(*map, 0), "RootObjectType") == "RobotRaconteurServiceIndex.ServiceIndex");
    const Structure& svc = info_at(*map, 1);
    CHECK(str_field(svc, "Name") == "svc");
    CHECK(str_field(svc, "RootObjectType") == "example.rawtest.Obj");
    const std::string url = base + "?nodeid=" + node->node_id().to_string() + "&service=svc";
    const auto* urls = svc.find("ConnectionURL")->get_if<MapInt32>();
    REQUIRE(urls);
    REQUIRE(urls->entries.size() == 1);
    CHECK(urls->entries[0].first == 1);
    CHECK(*urls->entries[0].second.get_if<std::string>() == url);
    const auto* attrs = svc.find("Attributes")->get_if<MapString>();
    REQUIRE(attrs);
    REQUIRE(attrs->entries.size() == 2);
    CHECK(*attrs->find("location")->get_if<std::string>() == "lab 2");
    CHECK(attrs->find("gain") != nullptr);
    CHECK(attrs->find("tags") == nullptr);

    auto routed = root.call("GetRoutedNodes");
    REQUIRE(routed);
    CHECK(routed->get_if<MapInt32>()->entries.empty());

    // The reported URL leads to the service.
    auto direct = Client::connect(io.executor(), url);
    REQUIRE(direct);
    CHECK((*direct)->root().type() == "example.rawtest.Obj");
    CHECK((*direct)->close_wait().ok());

    // The list follows registrations, and the index's clients hear of each change.
    std::atomic<int> changes{0};
    auto sub = root.subscribe("LocalNodeServicesChanged", [&](const std::string&, std::vector<Value>&) { ++changes; });
    REQUIRE(sub);
    node->unregister_service("svc");
    CHECK(rr::testing::eventually([&] { return changes.load() >= 1; }));
    CHECK(changes.load() == 1);
    node->unregister_service("svc");  // nothing to remove: no event
    // A real change after it: its event comes after any the no-op would have sent (one session, in order).
    REQUIRE(node->register_service(std::make_shared<AttributedService>()));
    CHECK(rr::testing::eventually([&] { return changes.load() >= 2; }));
    CHECK(changes.load() == 2);
    node->unregister_service("svc");
    CHECK(rr::testing::eventually([&] { return changes.load() >= 3; }));
    r = root.call("GetLocalNodeServices");
    REQUIRE(r);
    REQUIRE(r->get_if<MapInt32>()->entries.size() == 1);
    CHECK(str_field(info_at(*r->get_if<MapInt32>(), 0), "Name") == "RobotRaconteurServiceIndex");
    CHECK((*c)->close_wait().ok());
    node->shutdown();
}

TEST_CASE("node: find_service answers RobotRaconteurServiceIndex with the built-in index") {
    auto node = server::Node::create(server::NodeOptions{NodeID(), "indextest.node", 2, {}, 0, 5000ms});
    auto builtin = node->find_service("RobotRaconteurServiceIndex");
    REQUIRE(builtin);
    CHECK(builtin->root_type().object_type == "RobotRaconteurServiceIndex.ServiceIndex");
    CHECK(node->find_service("NoSuchService") == nullptr);
    node->shutdown();
}

TEST_CASE("node: tcp_base_url brackets IPv6 and drops the scope") {
    using boost::asio::ip::tcp;
    CHECK(server::tcp_base_url(tcp::endpoint(boost::asio::ip::make_address("10.1.2.3"), 48653)) ==
          "rr+tcp://10.1.2.3:48653/");
    CHECK(server::tcp_base_url(tcp::endpoint(boost::asio::ip::make_address("fe80::1%1"), 2)) == "rr+tcp://[fe80::1]:2/");
    CHECK(server::tcp_base_url(tcp::endpoint(boost::asio::ip::make_address("::1"), 7)) == "rr+tcp://[::1]:7/");
}
