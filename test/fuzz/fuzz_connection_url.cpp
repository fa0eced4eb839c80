// libFuzzer target for connection URLs (base/names/connection_url.hpp) and NodeIDs (node_id.hpp):
// what parses must print to text that parses back to the same URL, and NodeID text must round-trip.
// Input: the URL text. Seeds: test/fuzz/seeds/fuzz_connection_url (the URLs of connection_url_test).
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string_view>

#include "base/names/connection_url.hpp"
#include "base/names/node_id.hpp"

namespace {

void check(bool ok, const char* what) {
    if (!ok) {
        std::fprintf(stderr, "fuzz_connection_url: %s\n", what);
        std::abort();
    }
}

bool same(const rr::ConnectionUrl& a, const rr::ConnectionUrl& b) {
    return a.scheme == b.scheme && a.host == b.host && a.port == b.port && a.path == b.path && a.user == b.user &&
           a.node_id == b.node_id && a.node_name == b.node_name && a.service == b.service;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size > 4096) return 0;
    const std::string_view text(reinterpret_cast<const char*>(data), size);

    if (auto id = rr::NodeID::parse(text)) {
        auto again = rr::NodeID::parse(id->to_string());
        check(again.ok() && *again == *id, "NodeID text does not parse back to the same id");
    }

    auto url = rr::parse_connection_url(text);
    if (!url) return 0;
    check(!url->scheme.empty(), "a parsed URL has a scheme");
    const std::string printed = url->to_string();
    auto back = rr::parse_connection_url(printed);
    check(back.ok(), "to_string() of a parsed URL does not parse");
    check(same(*url, *back), "to_string() of a parsed URL parses to a different URL");
    check(back->to_string() == printed, "to_string() is not stable");
    (void)url->is_websocket();
    (void)url->is_tls();
    return 0;
}
