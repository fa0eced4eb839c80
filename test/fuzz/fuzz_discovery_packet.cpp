// libFuzzer target for node discovery datagrams (core/discovery): the first byte picks the sender's
// address (IPv6 link-local, IPv4, IPv4-mapped, loopback), the rest is the datagram. Whatever parses must
// satisfy the checks CORE applies (URL ≤ 256 bytes naming the same NodeID, NodeName ≤ 128, nonce < 32),
// re-format to an announce that parses to the same node, and feed a small NodeTable that never grows
// past its caps. Any violation aborts. Seeds: test/fuzz/seeds/fuzz_discovery_packet.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "core/discovery/discovery_packet.hpp"
#include "core/discovery/node_table.hpp"
#include "base/names/connection_url.hpp"

namespace {

using namespace rr;
using namespace rr::discovery;

void check(bool ok) {
    if (!ok) std::abort();
}

NodeTable& table() {
    static NodeTable t([] {
        NodeTableLimits l;
        l.max_nodes = 8;
        l.max_urls_per_node = 2;
        return l;
    }());
    return t;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size == 0) return 0;
    static const char* const kSources[] = {"fe80::1", "10.0.0.9", "::ffff:10.0.0.9", "::1", "fec0::2", "192.168.7.1"};
    const auto source = PacketSource{*parse_ip_address(kSources[data[0] % std::size(kSources)])};
    const std::string_view datagram(reinterpret_cast<const char*>(data + 1), size - 1);
    static MonoTime now{};
    now += std::chrono::milliseconds(700);

    auto r = parse_packet(datagram, source, NodeID(), NodeID());
    if (auto* rej = std::get_if<Reject>(&r)) {
        check(!reject_name(*rej).empty());
        table().note_rejected(*rej);
        return 0;
    }
    auto& packet = std::get<Packet>(r);
    if (auto* a = std::get_if<Announce>(&packet)) {
        check(!a->node_id.is_any());
        check(a->url.size() <= kMaxUrlLength);
        check(a->node_name.size() <= kMaxNodeNameLength);
        check(a->service_state_nonce.size() < kMaxNonceLength);
        auto url = parse_connection_url(a->url);
        check(url && url->node_id == a->node_id);
        // Our own announce for the same node parses back to the same node.
        auto addr = parse_ip_address(url->host);
        check(addr.has_value());
        auto again = format_announce(a->node_id, a->node_name.find('\n') == std::string::npos ? a->node_name : "",
                                     url->scheme, *addr, url->port, a->service_state_nonce);
        auto r2 = parse_packet(again, PacketSource{*addr}, NodeID(), NodeID());
        if (auto* p2 = std::get_if<Packet>(&r2)) check(std::get<Announce>(*p2).node_id == a->node_id);

        NodeAnnouncement n{a->node_id, a->node_name, {a->url}, a->service_state_nonce, NodeSource::udp};
        table().node_detected(n, now, static_cast<std::uint32_t>(size));
        table().set_want_services(true, now);
        for (const auto& id : table().take_due_updates(now)) table().services_failed(id, "fuzz", now, 1);
        table().expire(now);
        check(table().size() <= 8);
        for (const auto& [id, e] : table().nodes()) check(!e.urls.empty() && e.urls.size() <= 2);
    }
    return 0;
}
