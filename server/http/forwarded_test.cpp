#include "server/http/forwarded.hpp"

#include <catch2/catch.hpp>

using namespace rr::server::http;
using boost::asio::ip::make_address;

namespace {
std::vector<IpNetwork> nets(std::initializer_list<const char*> texts) {
    std::vector<IpNetwork> out;
    for (auto t : texts) {
        auto n = parse_ip_network(t);
        REQUIRE(n);
        out.push_back(*n);
    }
    return out;
}
}  // namespace

TEST_CASE("forwarded: trusted proxy ranges parse, hosts, bad prefixes and garbage do not") {
    CHECK(parse_ip_network("127.0.0.1")->prefix_bits == 32);
    CHECK(parse_ip_network("10.0.0.0/8")->prefix_bits == 8);
    CHECK(parse_ip_network("::1")->prefix_bits == 128);
    CHECK(parse_ip_network("fd00::/8")->prefix_bits == 8);
    CHECK_FALSE(parse_ip_network("proxy.example.org"));
    CHECK_FALSE(parse_ip_network("10.0.0.0/33"));
    CHECK_FALSE(parse_ip_network("10.0.0.0/"));
    CHECK_FALSE(parse_ip_network("10.0.0.0/x"));
    CHECK_FALSE(parse_ip_network(""));
    auto t = nets({"10.0.0.0/8", "192.168.1.7", "fd00::/8"});
    CHECK(in_networks(t, make_address("10.200.3.4")));
    CHECK(in_networks(t, make_address("::ffff:10.1.2.3")));  // IPv4-mapped
    CHECK(in_networks(t, make_address("192.168.1.7")));
    CHECK_FALSE(in_networks(t, make_address("192.168.1.8")));
    CHECK_FALSE(in_networks(t, make_address("11.0.0.1")));
    CHECK(in_networks(t, make_address("fd12::1")));
    CHECK_FALSE(in_networks(t, make_address("fe80::1")));
    CHECK_FALSE(in_networks({}, make_address("127.0.0.1")));
}

TEST_CASE("forwarded: headers from a peer that is not a trusted proxy are ignored") {
    auto t = nets({"10.0.0.1"});
    auto o = client_origin(make_address("203.0.113.5"), 4242, "198.51.100.1", "https", t);
    CHECK(o.address == "203.0.113.5:4242");
    CHECK(o.scheme.empty());
    CHECK_FALSE(o.forwarded);
    // nothing configured: nobody is trusted
    o = client_origin(make_address("127.0.0.1"), 1, "198.51.100.1", "https", {});
    CHECK(o.address == "127.0.0.1:1");
    CHECK_FALSE(o.forwarded);
}

TEST_CASE("forwarded: from a trusted proxy, the rightmost untrusted X-Forwarded-For entry and the scheme") {
    auto t = nets({"10.0.0.0/8"});
    auto o = client_origin(make_address("10.0.0.1"), 4242, "198.51.100.1", "https", t);
    CHECK(o.address == "198.51.100.1");
    CHECK(o.scheme == "https");
    CHECK(o.forwarded);
    // a client that writes its own X-Forwarded-For cannot choose its address: the proxy appends the real one
    o = client_origin(make_address("10.0.0.1"), 4242, "1.2.3.4, 198.51.100.1", "http", t);
    CHECK(o.address == "198.51.100.1");
    CHECK(o.scheme == "http");
    // a chain of trusted proxies is walked past
    o = client_origin(make_address("10.0.0.1"), 4242, "198.51.100.1, 10.0.0.9, 10.0.0.8", "HTTPS, http", t);
    CHECK(o.address == "198.51.100.1");
    CHECK(o.scheme == "https");
    // IPv6 forms and ports as some proxies write them
    o = client_origin(make_address("10.0.0.1"), 1, "[2001:db8::5]:1234", "", t);
    CHECK(o.address == "2001:db8::5");
    CHECK(o.scheme.empty());
    o = client_origin(make_address("10.0.0.1"), 1, "198.51.100.9:555", "", t);
    CHECK(o.address == "198.51.100.9");
}

TEST_CASE("forwarded: a trusted proxy without headers, or with garbage in them, gives the proxy or the last good entry") {
    auto t = nets({"10.0.0.0/8"});
    auto o = client_origin(make_address("10.0.0.1"), 4242, "", "", t);
    CHECK(o.address == "10.0.0.1:4242");
    CHECK(o.forwarded);
    o = client_origin(make_address("10.0.0.1"), 4242, "not-an-address", "gopher", t);
    CHECK(o.address == "10.0.0.1:4242");
    CHECK(o.scheme.empty());
    o = client_origin(make_address("10.0.0.1"), 4242, "198.51.100.1, junk, 10.0.0.7", "", t);
    CHECK(o.address == "10.0.0.7");  // all trusted up to the garbage: the last good entry
    o = client_origin(make_address("10.0.0.1"), 4242, std::string(10000, ','), "", t);
    CHECK(o.address == "10.0.0.1:4242");
}
