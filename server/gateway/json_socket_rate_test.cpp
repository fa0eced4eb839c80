// Rate-limited subscriptions on the JSON WebSocket (docs/json-api.md "Rate and queue length") against
// rr_interop_service behind a Gateway: a burst through a wire and a pipe, checked by events (the last
// value arrives) and counts that hold at any speed (fewer than sent, in order, drops accounted for).
// How close the spacing is to 1/max_rate_hz is not checked here (that would be a `timing` test).
#include <algorithm>
#include <functional>
#include <map>

#include "server/gateway/json_api_test_fixture.hpp"
#include "test/support/eventually.hpp"

using namespace rr;
using namespace rr::server;
using namespace rr::server::gateway;
using namespace rr::server::gateway::testing;

namespace {

json member(std::string op_name, std::string m, json more = json::object()) {
    more["op"] = std::move(op_name);
    more["device"] = "interop";
    more["member"] = std::move(m);
    return more;
}
std::string error_of(const json& reply) {
    return reply.contains("error") ? reply["error"]["name"].get<std::string>() + ": " + reply["error"]["message"].get<std::string>()
                                   : "<no error: " + reply.dump() + ">";
}

}  // namespace

TEST_CASE("json socket rate: a wire at max_rate_hz 1: fewer values than an unlimited subscriber got, in order, the last one delivered") {
    RR_SKIP_WITHOUT_INTEROP_SERVICE();
    InteropProcess device;
    TestGateway gw(device.url());
    WsClient ws(gw.port());

    // The sender's subscription (no limit) and the rate-limited one, on the same wire: w_both echoes
    // every value the gateway sends to it.
    auto plain = ws.request(member("subscribe", "w_both"));
    REQUIRE(plain.contains("result"));
    auto limited = ws.request(member("subscribe", "w_both", {{"max_rate_hz", 1}}));
    INFO(limited.dump());
    REQUIRE(limited.contains("result"));
    CHECK(limited["result"]["max_rate_hz"] == 1);
    const auto sender = plain["result"]["subscription"].get<std::uint64_t>();
    const auto sid = limited["result"]["subscription"].get<std::uint64_t>();

    // Paced: the next value is sent once the unlimited subscription got the previous one, so the socket
    // is never behind and nothing is coalesced by backpressure: every value reaches the unlimited
    // subscriber, and only the rate thins the other (at 1 Hz these would need 30 s to all go).
    constexpr int kValues = 30;
    std::vector<double> got, all;
    auto read_one = [&] {
        auto m = ws.next();
        REQUIRE(m);
        if (m->contains("id")) {
            INFO(m->dump());
            CHECK(m->contains("result"));
        } else if (m->value("kind", "") == "wire" && (*m)["value"].is_array() && !(*m)["value"].empty()) {
            const double v = (*m)["value"][0].get<double>();
            if (m->value("subscription", std::uint64_t{0}) == sid) got.push_back(v);
            if (m->value("subscription", std::uint64_t{0}) == sender) all.push_back(v);
        }
    };
    for (int i = 0; i < kValues; ++i) {
        ws.send(json{{"id", 10000 + i}, {"op", "set_out_value"}, {"subscription", sender}, {"value", {double(i)}}});
        while (all.empty() || all.back() != i) read_one();
    }
    while (got.empty() || got.back() != kValues - 1) read_one();  // the trailing send of the last window
    INFO("unlimited: " << json(all).dump() << "; at 1 Hz: " << json(got).dump());
    CHECK(got.size() < std::size_t(kValues) / 2);
    CHECK(std::is_sorted(got.begin(), got.end()));
    CHECK(std::adjacent_find(got.begin(), got.end()) == got.end());
    // The socket's counters, once the last value arrived: the rest were replaced while they waited.
    const auto stats = gw.sockets().stats();
    REQUIRE(stats.size() == 1);
    CHECK(stats[0].wire_coalesced > 0);
}

TEST_CASE("json socket rate: a burst to a socket often behind: each wire subscription's values arrive in order, the last one too") {
    // A value for a socket that keeps up is sent in the critical section that offers it (on the
    // device's thread); one for a socket that is behind waits for the retry timer's flusher, and a
    // rate-limited one for its window's. A queue threshold of one message makes a fast burst mix them.
    using namespace std::chrono_literals;
    RR_SKIP_WITHOUT_INTEROP_SERVICE();
    InteropProcess device;
    JsonSocketOptions options;
    options.wire_queue_threshold = 1;
    options.wire_retry = 1ms;
    TestGateway gw(device.url(), true, options);
    WsClient driver(gw.port());
    WsClient ws(gw.port());
    auto own = driver.request(member("subscribe", "w_both"));
    REQUIRE(own.contains("result"));
    const auto sender = own["result"]["subscription"].get<std::uint64_t>();
    std::vector<std::uint64_t> sids;
    for (const json& more : {json::object(), json{{"max_rate_hz", 200}}, json::object()}) {
        auto r = ws.request(member("subscribe", "w_both", more));
        INFO(r.dump());
        REQUIRE(r.contains("result"));
        sids.push_back(r["result"]["subscription"].get<std::uint64_t>());
    }

    constexpr int kValues = 400;
    for (int i = 1; i <= kValues; ++i)
        driver.send(json{{"id", i}, {"op", "set_out_value"}, {"subscription", sender}, {"value", {double(i)}}});
    std::map<std::uint64_t, std::vector<double>> got;
    auto all_last = [&] {
        return std::all_of(sids.begin(), sids.end(), [&](auto sid) { return !got[sid].empty() && got[sid].back() == kValues; });
    };
    while (!all_last()) {
        auto m = ws.next();
        REQUIRE(m);
        if (m->value("kind", "") == "wire" && (*m)["value"].is_array() && !(*m)["value"].empty())
            got[m->value("subscription", std::uint64_t{0})].push_back((*m)["value"][0].get<double>());
    }
    for (auto sid : sids) {
        const auto& v = got[sid];
        INFO("subscription " << sid << ": " << v.size() << " values: " << json(v).dump());
        CHECK(std::adjacent_find(v.begin(), v.end(), std::greater_equal<>()) == v.end());  // strictly increasing
    }
}

TEST_CASE("json socket rate: a pipe at max_rate_hz 2 with queue_length 3 keeps the newest packets, drops are counted") {
    RR_SKIP_WITHOUT_INTEROP_SERVICE();
    InteropProcess device;
    TestGateway gw(device.url());
    WsClient ws(gw.port());
    auto r = ws.request(member("subscribe", "p_stream", {{"max_rate_hz", 2}, {"queue_length", 3}}));
    INFO(r.dump());
    REQUIRE(r.contains("result"));
    CHECK(r["result"]["queue_length"] == 3);
    const auto sid = r["result"]["subscription"].get<std::uint64_t>();

    constexpr int kPackets = 50;
    CHECK(ws.request(member("call", "send_stream", {{"args", {kPackets}}})).contains("result"));
    std::vector<double> got;
    std::uint64_t dropped = 0;
    while (got.empty() || got.back() != kPackets - 1) {
        auto p = ws.wait_push([&](const json& j) { return j.value("subscription", std::uint64_t{0}) == sid && j["kind"] == "pipe"; });
        REQUIRE(p);
        got.push_back((*p)["value"][0].get<double>());
        dropped += p->value("dropped", std::uint64_t{0});
    }
    INFO("packets delivered: " << json(got).dump());
    CHECK(got.size() < std::size_t(kPackets));
    CHECK(std::is_sorted(got.begin(), got.end()));
    CHECK(std::adjacent_find(got.begin(), got.end()) == got.end());
    // The last three were queued together and leave one per window; every other packet is accounted for.
    REQUIRE(got.size() >= 3);
    CHECK(got[got.size() - 3] == kPackets - 3);
    CHECK(got.size() + dropped == std::size_t(kPackets));
}

TEST_CASE("json socket rate: max_rate_hz on an event and queue_length on a wire are refused with the reason") {
    RR_SKIP_WITHOUT_INTEROP_SERVICE();
    InteropProcess device;
    TestGateway gw(device.url());
    WsClient ws(gw.port());
    CHECK(error_of(ws.request(member("subscribe", "ev_values", {{"max_rate_hz", 5}}))) ==
          "RobotRaconteur.InvalidArgument: \"max_rate_hz\" applies to wires and pipes; every event of \"ev_values\" is delivered");
    CHECK(error_of(ws.request(member("subscribe", "w_state", {{"max_rate_hz", 5}, {"queue_length", 2}}))) ==
          "RobotRaconteur.InvalidArgument: \"queue_length\" applies to pipes; a wire keeps its newest value");
    CHECK(error_of(ws.request(member("subscribe", "w_state", {{"max_rate_hz", 0}}))) ==
          "RobotRaconteur.InvalidArgument: \"max_rate_hz\" must be a number from 0.01 to 1000");
    // The socket carries on: a good subscription still works, and nothing was left open by the refusals.
    auto ok = ws.request(member("subscribe", "w_state", {{"max_rate_hz", 5}}));
    CHECK(ok.contains("result"));
    const auto stats = gw.sockets().stats();
    REQUIRE(stats.size() == 1);
    CHECK(stats[0].subscriptions == 1);
}

TEST_CASE("json socket rate: subscriptions of one wire at one rate form one rate group across sockets, each gets the last value, leaving ends the group") {
    RR_SKIP_WITHOUT_INTEROP_SERVICE();
    InteropProcess device;
    TestGateway gw(device.url());
    WsClient a(gw.port()), b(gw.port());
    auto plain = a.request(member("subscribe", "w_both"));
    REQUIRE(plain.contains("result"));
    const auto sender = plain["result"]["subscription"].get<std::uint64_t>();
    auto a5 = a.request(member("subscribe", "w_both", {{"max_rate_hz", 5}}));
    auto a2 = a.request(member("subscribe", "w_both", {{"max_rate_hz", 2}}));  // the same socket at a second rate
    auto b5 = b.request(member("subscribe", "w_both", {{"max_rate_hz", 5}}));
    INFO(a5.dump() << " " << a2.dump() << " " << b5.dump());
    REQUIRE((a5.contains("result") && a2.contains("result") && b5.contains("result")));
    CHECK(gw.sockets().rate_groups() == 2);  // (w_both, 5 Hz) shared by both sockets, (w_both, 2 Hz)

    // A burst: every rate-limited subscription ends with the last value.
    constexpr int kValues = 20;
    for (int i = 0; i < kValues; ++i)
        a.send(json{{"id", 20000 + i}, {"op", "set_out_value"}, {"subscription", sender}, {"value", {double(i)}}});
    auto last_of = [&](WsClient& ws, std::uint64_t sid) {
        return ws.wait_push([&](const json& j) {
            return j.value("subscription", std::uint64_t{0}) == sid && j.value("kind", "") == "wire" && j["value"].is_array() &&
                   !j["value"].empty() && j["value"][0].get<double>() == kValues - 1;
        });
    };
    CHECK(last_of(b, b5["result"]["subscription"].get<std::uint64_t>()).has_value());
    CHECK(last_of(a, a2["result"]["subscription"].get<std::uint64_t>()).has_value());

    // The 2 Hz group ends with its only member; the 5 Hz one when both of its members are gone.
    CHECK(a.request(json{{"op", "unsubscribe"}, {"subscription", a2["result"]["subscription"]}}).contains("result"));
    CHECK(gw.sockets().rate_groups() == 1);
    CHECK(a.request(json{{"op", "unsubscribe"}, {"subscription", a5["result"]["subscription"]}}).contains("result"));
    CHECK(gw.sockets().rate_groups() == 1);
    b.close();
    CHECK(rr::testing::eventually([&] { return gw.sockets().rate_groups() == 0; }));
}
