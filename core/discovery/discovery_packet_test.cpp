#include <catch2/catch.hpp>

#include "core/discovery/discovery_packet.hpp"

using namespace rr;
using namespace rr::discovery;

namespace {

const char* kId = "{d835c41d-339c-47a8-84db-f00a8fefd2fa}";
const char* kIdPlain = "d835c41d-339c-47a8-84db-f00a8fefd2fa";

PacketSource from(const char* ip) { return PacketSource{*parse_ip_address(ip)}; }

std::string announce(const std::string& id_line, const std::string& url, const std::string& extra = "") {
    return std::string(kAnnounceMagic) + "\n" + id_line + "\n" + url + "\n" + extra;
}

std::string url6(const char* host = "fe80::1", const char* id = kIdPlain) {
    return std::string("rr+tcp://[") + host + "]:4242/?nodeid=" + id + "&service=RobotRaconteurServiceIndex";
}

Reject rejected(const std::string& packet, const PacketSource& src, NodeID own = {}) {
    auto r = parse_packet(packet, src, own, NodeID());
    REQUIRE(std::holds_alternative<Reject>(r));
    return std::get<Reject>(r);
}

Announce accepted(const std::string& packet, const PacketSource& src) {
    auto r = parse_packet(packet, src, NodeID(), NodeID());
    if (auto* rej = std::get_if<Reject>(&r)) FAIL("rejected: " << reject_name(*rej));
    auto& p = std::get<Packet>(r);
    REQUIRE(std::holds_alternative<Announce>(p));
    return std::get<Announce>(p);
}

}  // namespace

TEST_CASE("discovery: IP literals parse and print as the official announces write them") {
    CHECK(parse_ip_address("192.168.1.20")->to_string() == "192.168.1.20");
    CHECK(parse_ip_address("fe80::1")->to_string() == "fe80::1");
    CHECK(parse_ip_address("FE80:0:0:0:0200:5EFF:FE00:5301%eth0")->to_string() == "fe80::200:5eff:fe00:5301");
    CHECK(parse_ip_address("::")->to_string() == "::");
    CHECK(parse_ip_address("::ffff:10.1.2.3")->is_v4_mapped());
    CHECK(parse_ip_address("1:0:0:2:0:0:0:3")->to_string() == "1:0:0:2::3");
    CHECK(parse_ip_address("::1")->is_loopback());
    CHECK(parse_ip_address("127.0.0.5")->is_loopback());
    CHECK(parse_ip_address("fe80::1")->is_link_local());
    CHECK(parse_ip_address("fec0::1")->is_site_local());
    CHECK_FALSE(parse_ip_address("2001:db8::1")->is_link_local());
    for (const char* bad : {"", "localhost", "1.2.3", "1.2.3.256", "1.2.3.4.5", "::1::2", "1:2:3:4:5:6:7:8:9", ":1::",
                            "12345::", "fe80::1%", "1.2.3.4:80", "[::1]"})
        CHECK_FALSE(parse_ip_address(bad));
}

TEST_CASE("discovery: our announce is the official text and reads back") {
    auto id = *NodeID::parse(kId);
    auto text = format_announce(id, "my.node", "rr+tcp", *parse_ip_address("fe80::1"), 4242, "abcdEFGH01234567");
    CHECK(text == std::string(kAnnounceMagic) + "\n" + kId + ",my.node\n" + url6() +
                      "\nServiceStateNonce: abcdEFGH01234567\n");
    auto a = accepted(text, from("fe80::99"));
    CHECK(a.node_id == id);
    CHECK(a.node_name == "my.node");
    CHECK(a.url == url6());
    CHECK(a.service_state_nonce == "abcdEFGH01234567");

    auto v4 = format_announce(id, "", "rr+tcp", *parse_ip_address("10.0.3.7"), 80, "n");
    CHECK(v4 == std::string(kAnnounceMagic) + "\n" + kId + "\nrr+tcp://10.0.3.7:80/?nodeid=" + kIdPlain +
                    "&service=RobotRaconteurServiceIndex\nServiceStateNonce: n\n");
    CHECK(accepted(v4, from("10.0.200.1")).node_name.empty());

    // The nonce line is left out when it would make the packet longer than 2048 bytes.
    auto long_name = std::string(1850, 'n');
    auto big = format_announce(id, long_name, "rr+tcp", *parse_ip_address("10.0.3.7"), 80, "abcdEFGH01234567");
    CHECK(big.find("ServiceStateNonce") == std::string::npos);
    CHECK(big.size() <= kMaxAnnounceWithNonce);
}

TEST_CASE("discovery: request packets carry the request UUID line") {
    auto rid = *NodeID::parse(kId);
    auto text = format_request(rid);
    CHECK(text == std::string(kRequestMagic) + "\n" + kId + "\n");
    auto r = parse_packet(text, from("fe80::2"), NodeID(), NodeID());
    REQUIRE(std::holds_alternative<Packet>(r));
    CHECK(std::get<Request>(std::get<Packet>(r)).request_id == rid);
    // Our own request is ignored; a request with only the magic line is too short for CORE.
    CHECK(std::get<Reject>(parse_packet(text, from("fe80::2"), NodeID(), rid)) == Reject::own_packet);
    CHECK(std::get<Reject>(parse_packet(std::string(kRequestMagic) + "\n", from("fe80::2"), NodeID(), NodeID())) ==
          Reject::truncated);
}

TEST_CASE("discovery: hostile and malformed announces are rejected with a reason") {
    auto src6 = from("fe80::99");
    CHECK(rejected("hello", src6) == Reject::not_discovery);
    CHECK(rejected(std::string(kMaxDatagram + 1, 'x'), src6) == Reject::oversized);
    CHECK(rejected(announce(kId, url6()) + std::string(kMaxDatagram, ' '), src6) == Reject::oversized);
    CHECK(rejected(std::string(kAnnounceMagic), src6) == Reject::truncated);
    CHECK(rejected(std::string(kAnnounceMagic) + "\n" + kId, src6) == Reject::truncated);
    CHECK(rejected(announce("{d835c41d-339c-47a8-84db-f00a8fefd2f}", url6()), src6) == Reject::bad_node_id);
    CHECK(rejected(announce("{zz35c41d-339c-47a8-84db-f00a8fefd2fa},x", url6()), src6) == Reject::bad_node_id);
    CHECK(rejected(announce("{00000000-0000-0000-0000-000000000000}",
                            url6("fe80::1", "00000000-0000-0000-0000-000000000000")),
                   src6) == Reject::bad_node_id);
    CHECK(rejected(announce(kId, url6() + std::string(300, 'a')), src6) == Reject::url_too_long);
    CHECK(rejected(announce(kId, "bogus://x"), src6) == Reject::bad_url);
    CHECK(rejected(announce(kId, "rr+tcp://[fe80::1:4242/?nodeid=x"), src6) == Reject::bad_url);
    CHECK(rejected(announce(kId, std::string("rr+tcp://evil.example.org:4242/?nodeid=") + kIdPlain), src6) ==
          Reject::not_ip_literal);
    // Lying URLs: another node's id, an address of another family, a global address, another subnet.
    CHECK(rejected(announce(kId, url6("fe80::1", "11111111-339c-47a8-84db-f00a8fefd2fa")), src6) ==
          Reject::node_id_mismatch);
    CHECK(rejected(announce(kId, std::string("rr+tcp://10.0.0.1:4242/?nodeid=") + kIdPlain), src6) ==
          Reject::family_mismatch);
    CHECK(rejected(announce(kId, url6("2001:db8::1")), src6) == Reject::not_link_local);
    CHECK(rejected(announce(kId, std::string("rr+tcp://10.1.0.1:4242/?nodeid=") + kIdPlain), from("10.2.0.1")) ==
          Reject::subnet_mismatch);
    // Own NodeID.
    CHECK(rejected(announce(kId, url6()), src6, *NodeID::parse(kId)) == Reject::own_packet);
}

TEST_CASE("discovery: announce details as CORE reads them") {
    auto src6 = from("fe80::99");
    // Loopback URLs are accepted from any source; an IPv4 sender on a dual-stack socket is unmapped.
    CHECK(accepted(announce(kId, std::string("rr+tcp://127.0.0.1:1/?nodeid=") + kIdPlain), src6).url.size() > 0);
    CHECK(accepted(announce(kId, std::string("rr+tcp://10.1.0.1:4242/?nodeid=") + kIdPlain), from("::ffff:10.1.9.9"))
              .node_id == *NodeID::parse(kId));
    // A NodeName over 128 bytes is dropped, the node kept; only the first ',' field is the name.
    CHECK(accepted(announce(std::string(kId) + "," + std::string(129, 'a'), url6()), src6).node_name.empty());
    CHECK(accepted(announce(std::string(kId) + ",a,b", url6()), src6).node_name == "a");
    // Attribute lines: spaces around, unknown names ignored, nonces of 32 bytes or more ignored.
    CHECK(accepted(announce(kId, url6(), "  ServiceStateNonce :  xyz  \nOther: 1\n"), src6).service_state_nonce == "xyz");
    CHECK(accepted(announce(kId, url6(), "ServiceStateNonce: " + std::string(32, 'x') + "\n"), src6)
              .service_state_nonce.empty());
    CHECK(accepted(announce(kId, url6(), "garbage line\n\n\n"), src6).service_state_nonce.empty());
    // CORE checks only the magic prefix.
    CHECK(accepted(std::string(kAnnounceMagic) + " trailing\n" + kId + "\n" + url6(), src6).node_id ==
          *NodeID::parse(kId));
}

TEST_CASE("discovery: the service state nonce is 16 alphanumerics") {
    std::uint8_t random[16];
    for (int i = 0; i < 16; ++i) random[i] = static_cast<std::uint8_t>(i * 29 + 3);
    auto n = make_service_state_nonce(random);
    CHECK(n.size() == 16);
    for (char c : n) CHECK(((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9')));
    random[0] ^= 1;
    CHECK(make_service_state_nonce(random) != n);
}
