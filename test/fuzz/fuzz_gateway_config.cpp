// libFuzzer target for the gateway's YAML configuration (server/app/gateway_config.hpp): any text
// parses to a configuration or to an InvalidConfiguration error, never a crash, an escaping exception
// or unbounded recursion; a configuration that parses names valid device URLs with a service.
// Input: the YAML text. Seeds: test/fuzz/seeds/fuzz_gateway_config (from gateway_config_test and
// gateway-config/).
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string_view>

#include "base/names/connection_url.hpp"
#include "server/app/gateway_config.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size > 64 * 1024) return 0;
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    auto c = rr::server::app::parse_gateway_config(text, "fuzz.yaml");
    if (!c) {
        if (c.error().type != rr::MessageErrorType::InvalidConfiguration) {
            std::fprintf(stderr, "fuzz_gateway_config: unexpected error type: %s\n", c.error().message.c_str());
            std::abort();
        }
        return 0;
    }
    for (const auto& d : c->devices) {
        auto url = rr::parse_connection_url(d.url);
        if (!url || url->service.empty()) {
            std::fprintf(stderr, "fuzz_gateway_config: accepted device URL \"%s\"\n", d.url.c_str());
            std::abort();
        }
    }
    return 0;
}
