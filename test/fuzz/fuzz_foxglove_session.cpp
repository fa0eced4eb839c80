// libFuzzer target for the Foxglove WebSocket protocol's connection state (core/foxglove,
// docs/foxglove.md "Bad input"): the input is a sequence of client messages, each a byte saying text
// (even) or binary (odd), then its bytes up to the next 0xFF 0xFE pair. The session has advertised
// channels 1..8 and services 1..4. Checks: no crash or sanitizer report; every message the session
// answers with is a JSON object with an `op`; the bounds hold (subscriptions, client channels, calls in
// flight); every event names a subscription, channel or service the session knows.
// Seeds: test/fuzz/seeds/fuzz_foxglove_session.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string_view>

#include <nlohmann/json.hpp>

#include "core/foxglove/foxglove_session.hpp"

namespace {

void check(bool ok, const char* what) {
    if (!ok) {
        std::fprintf(stderr, "fuzz_foxglove_session: %s\n", what);
        std::abort();
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size > 1u << 16) return 0;
    rr::foxglove::SessionLimits limits;
    limits.max_subscriptions = 4;
    limits.max_client_channels = 3;
    limits.max_calls_in_flight = 2;
    limits.max_parameter_subscriptions = 5;
    rr::foxglove::Session session(limits);
    std::vector<rr::foxglove::Channel> channels;
    for (std::uint32_t i = 1; i <= 8; ++i) channels.push_back({i, "t" + std::to_string(i), "json", "S", "{}", "jsonschema"});
    session.channels_advertised(channels);
    std::vector<rr::foxglove::Service> services;
    for (std::uint32_t i = 1; i <= 4; ++i) services.push_back({i, "s" + std::to_string(i), "T", {}, {}});
    session.services_advertised(services);

    const std::string_view all(reinterpret_cast<const char*>(data), size);
    std::size_t at = 0;
    while (at < all.size()) {
        const bool binary = static_cast<unsigned char>(all[at]) & 1;
        ++at;
        std::size_t end = all.find("\xff\xfe", at);
        if (end == std::string_view::npos) end = all.size();
        const std::string message(all.substr(at, end - at));  // the events view it until the next one
        at = end == all.size() ? end : end + 2;
        auto out = binary ? session.feed_binary(message) : session.feed_text(message);
        for (const auto& t : out.texts) {
            auto j = nlohmann::json::parse(t, nullptr, false);
            check(!j.is_discarded() && j.is_object() && j.contains("op"), "an answer that is not a JSON object with an op");
        }
        for (const auto& e : out.events) {
            if (auto* s = std::get_if<rr::foxglove::event::Subscribed>(&e))
                check(session.channel_advertised(s->channel_id) && session.subscription_channel(s->subscription_id) == s->channel_id,
                      "a subscription to a channel the session does not hold");
            if (auto* p = std::get_if<rr::foxglove::event::ClientPublish>(&e))
                check(p->channel && session.client_channels().count(p->channel->id), "a publish on an unknown client channel");
            if (auto* c = std::get_if<rr::foxglove::event::ServiceCall>(&e)) {
                check(c->service_id >= 1 && c->service_id <= 4, "a call of a service never advertised");
                if (c->call_id % 2) session.call_finished(c->service_id, c->call_id);  // some answered, some not
            }
        }
        check(session.subscription_count() <= limits.max_subscriptions, "more subscriptions than the bound");
        check(session.client_channel_count() <= limits.max_client_channels, "more client channels than the bound");
        check(session.calls_in_flight() <= limits.max_calls_in_flight, "more calls in flight than the bound");
        if (!out.events.empty() && (out.events.size() & 3) == 0) session.channels_unadvertised({2, 3});
    }
    return 0;
}
