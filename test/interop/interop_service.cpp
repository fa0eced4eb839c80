// rr_interop_service: the interop test service (robdef/experimental.interop_test.robdef) implemented
// with our ObjectService, behaving exactly like official_service.py: the same values (a C++ port of
// interop_values.py), the same pushes (events, pipe packets, callbacks, wire values every 200 ms) and
// the same errors. official_client.py must pass every check against it.
//
// Usage:
//   rr_interop_service [--port N] [--websocket] [--disable-message4] [--enable-stringtable]
//                      [--heartbeat S] [--listen-all] [--max-lifetime S] [--robdef PATH]
//                      [--local-name NAME | --local] [--users FILE]
// When ready it prints one JSON line, like official_service.py:
//   {"url": "rr+tcp://127.0.0.1:PORT/?service=interop", "port": PORT, "nodeid": "...", ...}
// (with "ws_url": "rr+ws://127.0.0.1:PORT/?service=interop" under --websocket: RR over WebSocket on the
// same port, server/http). With --local-name NAME the node takes that NodeName (and the NodeID the
// NodeID cache gives it) and also serves rr+local (server/transport/local), adding "local_url"
// (by NodeName) and "local_id_url" (by NodeID) to the ready line; --local serves rr+local by NodeID
// only. A NodeName in use (or any other rr+local error) exits with status 3 and the message on stderr.
// --users FILE requires a login against that password file (CORE's format: `user md5hex privileges`);
// users with the `objectlock` privilege may lock objects (test/interop/locks_logins.py).
// and runs until SIGTERM / SIGINT (or --max-lifetime), then shuts the node down.
#include <condition_variable>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <sstream>
#include <thread>

#include "core/value/pack_value.hpp"
#include "server/http/http_server.hpp"
#include "server/transport/local/local_listener.hpp"
#include "server/node/node.hpp"
#include "server/service/callback_member.hpp"
#include "server/service/memory_member.hpp"
#include "server/service/object_service.hpp"
#include "server/service/pipe_member.hpp"
#include "server/service/wire_member.hpp"

#ifndef RR_INTEROP_ROBDEF
#define RR_INTEROP_ROBDEF "test/interop/robdef/experimental.interop_test.robdef"
#endif

using namespace rr;
using namespace rr::server;

namespace {

// ------------------------------------------------------------------------------------------------
// Values (interop_values.py)

const std::string kSvc = "experimental.interop_test";
std::string qn(std::string_view s) { return kSvc + "." + std::string(s); }

const std::string kUtf8Text = "Grüße, 世界! 🤖 \"quoted\" \\ tab\t newline\n end";
constexpr float kF32Max = std::numeric_limits<float>::max();
constexpr float kF32Tiny = std::numeric_limits<float>::denorm_min();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
const std::string kBaseName = "interop root";
constexpr std::int32_t kRoValue = 17;
const std::vector<std::int32_t> kChildIntKeys = {-1, 0, 7};
const std::vector<std::string> kChildStrKeys = {"alpha", "with space_and-dash"};
const std::string kCallbackLabel = "λ-label";
constexpr auto kStatePeriod = std::chrono::milliseconds(200);
constexpr std::size_t kMemDoubleLen = 100, kMemPodLen = 4, kMemNaLen = 5, kMemRoLen = 16;

template <Numeric T>
Value scalar(T v) {
    return Value::scalar<T>(v);
}
template <Numeric T>
Value array(std::vector<T> v) {
    return Value(NumericArray::adopt<T>(std::move(v)));
}
Value bools(std::initializer_list<bool> v) { return Value(NumericArray::from<bool>(v)); }
template <Numeric T>
Value fortran(std::vector<std::uint32_t> dims, std::vector<T> values) {
    return Value(MultiDimArray{std::move(dims), NumericArray::adopt<T>(std::move(values))});
}
Value str(std::string s) { return Value(std::move(s)); }
Value color(std::int32_t v) { return Value(Enum{qn("Color"), v}); }
enum : std::int32_t { kRed = 0, kGreen = 1, kBlue = 16, kMinus = -5 };

Value inner(std::int32_t i, std::optional<std::string> label = {}, std::optional<std::vector<double>> values = {}) {
    Structure s;
    s.type_name = qn("Inner");
    s.set("id", scalar<std::int32_t>(i));
    s.set("label", str(label ? *label : "inner " + std::to_string(i) + " é"));
    s.set("values", array<double>(values ? *values : std::vector<double>{double(i), i + 0.5, double(-i)}));
    return Value(std::move(s));
}

PodArray test_pods_array(std::size_t n, std::int32_t seed = 0) {
    PodArray a;
    a.type_name = qn("TestPod");
    a.field_names = {"x", "arr", "bounded", "inner", "inners", "vec", "c", "md"};
    for (std::size_t k = 0; k < n; ++k) {
        const std::int32_t s = seed + static_cast<std::int32_t>(k);
        const std::int32_t blen = (s % 6) + 1;
        std::vector<std::uint8_t> bounded;
        for (std::int32_t j = 0; j < blen; ++j) bounded.push_back(static_cast<std::uint8_t>((s * 7 + j) % 256));
        PodArray in;
        in.type_name = qn("PodInner");
        in.field_names = {"a", "b"};
        (void)in.push_back({scalar<std::int16_t>(static_cast<std::int16_t>(-32768 + s)), array<double>({0.5, -0.5, double(s)})});
        PodArray ins;
        ins.type_name = qn("PodInner");
        ins.field_names = {"a", "b"};
        for (std::int32_t j = 0; j < 2; ++j)
            (void)ins.push_back({scalar<std::int16_t>(static_cast<std::int16_t>(100 * j + s)),
                                 array<double>({double(j), double(j + s), -1.0})});
        (void)a.push_back({scalar<double>(1.25 * (s + 1)),
                           array<std::int32_t>({s, -s, std::numeric_limits<std::int32_t>::max(),
                                                std::numeric_limits<std::int32_t>::min()}),
                           array<std::uint8_t>(std::move(bounded)), Value(std::move(in)), Value(std::move(ins)),
                           Value(NamedArray{qn("Vec3"), NumericArray::from<double>({1.0 + s, -2.0, 0.125}), {}}),
                           scalar<cdouble>(cdouble(s, -0.75)),
                           Value(MultiDimArray{{2, 2}, NumericArray::from<double>({1.0, 3.0, 2.0, 4.0 + s})})});
    }
    return a;
}
Value test_pods(std::size_t n, std::int32_t seed = 0, std::vector<std::uint32_t> dims = {}) {
    PodArray a = test_pods_array(n, seed);
    a.dims = std::move(dims);
    return Value(std::move(a));
}

std::vector<double> vec3_numbers(std::size_t n, std::int32_t seed) {
    std::vector<double> v;
    for (std::size_t k = 0; k < n; ++k) {
        const std::int32_t s = seed + static_cast<std::int32_t>(k);
        v.push_back(s + 0.5);
        v.push_back(double(-s));  // integer negation first: -0 is +0.0, as numpy stores it
        v.push_back(1e-300 * (s + 1));
    }
    return v;
}
Value vec3s(std::size_t n, std::int32_t seed = 0, std::vector<std::uint32_t> dims = {}) {
    return Value(NamedArray{qn("Vec3"), NumericArray::adopt<double>(vec3_numbers(n, seed)), std::move(dims)});
}

Value poses(std::size_t n, std::int32_t seed = 0) {
    std::vector<double> v;
    for (std::size_t k = 0; k < n; ++k) {
        const std::int32_t s = seed + static_cast<std::int32_t>(k);
        for (double x : {double(s), s * 2.0, double(-s), 1.0, 0.0, 0.0, s * 0.25}) v.push_back(x);
    }
    return Value(NamedArray{qn("Pose"), NumericArray::adopt<double>(std::move(v)), {}});
}

Value list(std::vector<Value> items) { return Value(List{std::move(items)}); }

Value everything(int v, int depth = 0) {
    Structure s;
    s.type_name = qn("Everything");
    s.set("f_double", scalar<double>(v == 0 ? -1.7976931348623157e308 : 5e-324));
    s.set("f_single", scalar<float>(v == 0 ? kF32Max : kF32Tiny));
    s.set("f_int8", scalar<std::int8_t>(v == 0 ? -128 : 127));
    s.set("f_uint8", scalar<std::uint8_t>(v == 0 ? 255 : 0));
    s.set("f_int16", scalar<std::int16_t>(v == 0 ? -32768 : 32767));
    s.set("f_uint16", scalar<std::uint16_t>(v == 0 ? 65535 : 1));
    s.set("f_int32", scalar<std::int32_t>(v == 0 ? std::numeric_limits<std::int32_t>::min() : std::numeric_limits<std::int32_t>::max()));
    s.set("f_uint32", scalar<std::uint32_t>(v == 0 ? 4294967295u : 2u));
    s.set("f_int64", scalar<std::int64_t>(v == 0 ? std::numeric_limits<std::int64_t>::min() : std::numeric_limits<std::int64_t>::max()));
    s.set("f_uint64", scalar<std::uint64_t>(v == 0 ? std::numeric_limits<std::uint64_t>::max() : 3u));
    s.set("f_cdouble", scalar<cdouble>(v == 0 ? cdouble(1.5, -2.25) : cdouble(-0.0, 1e300)));
    s.set("f_csingle", scalar<csingle>(v == 0 ? csingle(0.5f, -0.25f) : csingle(kF32Max, kF32Tiny)));
    s.set("f_bool", scalar<bool>(v == 0));
    s.set("f_string", str(v == 0 ? kUtf8Text : ""));
    s.set("f_enum", color(v == 0 ? kBlue : kMinus));
    s.set("f_array", array<double>({1.0, 2.0, 3.5 + v}));
    s.set("f_fixed", array<double>({0.25, -0.25, 1e10 * (v + 1)}));
    std::vector<std::int16_t> bounded = {1, -1, 300};
    bounded.resize(3 - v);
    s.set("f_bounded", array<std::int16_t>(bounded));
    s.set("f_md", fortran<double>({2, 3}, {1, 2, 3, 4, 5, 6.0 + v}));
    s.set("f_inner", inner(10 + v));
    s.set("f_inner_null", Value());
    s.set("f_inner_list", v == 0 ? list({inner(1), inner(2, "")}) : list({}));
    s.set("f_inner_by_int", Value(MapInt32{{{-5, inner(5)}, {0, inner(0)}, {2147483647, inner(7)}}}));
    s.set("f_inner_by_name", v == 0 ? Value(MapString{{{"a", inner(1)}, {"üñî", inner(2)}}}) : Value(MapString{}));
    s.set("f_strings", v == 0 ? list({str("one"), str(""), str("三")}) : Value());
    s.set("f_pod", test_pods(1, v));
    s.set("f_vec", vec3s(1, v));
    s.set("f_vecs", vec3s(3 - v, 5));
    s.set("f_any", v == 0 ? array<std::int32_t>({1, 2, 3}) : str("text"));
    s.set("f_any_null", Value());
    s.set("f_self", depth == 0 ? everything(v, depth + 1) : Value());
    return Value(std::move(s));
}

const std::vector<std::string> kVarvalueKinds = {
    "double[]", "single[]", "int8[]", "uint8[]", "int16[]", "uint16[]", "int32[]", "uint32[]",
    "int64[]", "uint64[]", "cdouble[]", "csingle[]", "bool[]", "empty double[]", "double scalar",
    "string", "empty string", "double[*]", "int32[*]", "struct", "struct everything", "pod[]",
    "pod[*]", "namedarray[]", "namedarray[*]", "varvalue{list}", "varvalue{int32}",
    "varvalue{string}", "string{list}", "double{int32}", "nested", "null",
};

/// kind -> the value as it travels (the Python catalogue's sent and received forms pack the same).
std::map<std::string, Value> varvalue_catalog() {
    std::map<std::string, Value> c;
    c["double[]"] = array<double>({0.0, -0.0, 1.5, kInf, -kInf, kNaN, 5e-324});
    c["single[]"] = array<float>({kF32Max, -1.5f, kF32Tiny});
    c["int8[]"] = array<std::int8_t>({-128, 0, 127});
    c["uint8[]"] = array<std::uint8_t>({0, 1, 255});
    c["int16[]"] = array<std::int16_t>({-32768, 32767});
    c["uint16[]"] = array<std::uint16_t>({0, 65535});
    c["int32[]"] = array<std::int32_t>({std::numeric_limits<std::int32_t>::min(), std::numeric_limits<std::int32_t>::max()});
    c["uint32[]"] = array<std::uint32_t>({0, 4294967295u});
    c["int64[]"] = array<std::int64_t>({std::numeric_limits<std::int64_t>::min(), std::numeric_limits<std::int64_t>::max()});
    c["uint64[]"] = array<std::uint64_t>({0, std::numeric_limits<std::uint64_t>::max()});
    c["cdouble[]"] = array<cdouble>({cdouble(1, 2), cdouble(-0.5, -0.25)});
    c["csingle[]"] = array<csingle>({csingle(1, 2), csingle(-0.5f, -0.25f)});
    c["bool[]"] = bools({true, false, true});
    c["empty double[]"] = array<double>({});
    c["double scalar"] = scalar<double>(3.25);
    c["string"] = str(kUtf8Text);
    c["empty string"] = str("");
    c["double[*]"] = fortran<double>({2, 3}, {1, 2, 3, 4, 5, 6});
    c["int32[*]"] = fortran<std::int32_t>({2, 2, 2}, {0, 1, 2, 3, 4, 5, 6, 7});
    c["struct"] = inner(3);
    c["struct everything"] = everything(0);
    c["pod[]"] = test_pods(2, 3);
    c["pod[*]"] = test_pods(6, 1, {2, 3});
    c["namedarray[]"] = vec3s(2);
    c["namedarray[*]"] = vec3s(4, 0, {2, 2});
    c["varvalue{list}"] = list({str("a"), array<std::int32_t>({1}), Value()});
    c["varvalue{int32}"] = Value(MapInt32{{{-1, str("minus one")}, {2147483647, array<double>({2.0})}}});
    c["varvalue{string}"] = Value(MapString{{{"k", str("v")}, {"ü", array<std::uint8_t>({7})}}});
    c["string{list}"] = list({str("x"), str("ÿ")});
    c["double{int32}"] = Value(MapInt32{{{3, scalar<double>(1.5)}, {-4, scalar<double>(2.5)}}});
    c["nested"] = Value(MapString{{{"list", list({Value(MapString{{{"deep", inner(9)}}})})}}});
    c["null"] = Value();
    return c;
}

/// name -> (A, B): the property values (interop_values.property_values).
std::vector<std::pair<std::string, std::pair<Value, Value>>> property_values() {
    using I32 = std::numeric_limits<std::int32_t>;
    std::vector<std::pair<std::string, std::pair<Value, Value>>> p;
    auto add = [&](std::string name, Value a, Value b) { p.emplace_back(std::move(name), std::make_pair(std::move(a), std::move(b))); };
    add("p_double", scalar<double>(-1.7976931348623157e308), scalar<double>(5e-324));
    add("p_single", scalar<float>(kF32Max), scalar<float>(-kF32Tiny));
    add("p_int8", scalar<std::int8_t>(-128), scalar<std::int8_t>(127));
    add("p_uint8", scalar<std::uint8_t>(255), scalar<std::uint8_t>(0));
    add("p_int16", scalar<std::int16_t>(-32768), scalar<std::int16_t>(32767));
    add("p_uint16", scalar<std::uint16_t>(65535), scalar<std::uint16_t>(0));
    add("p_int32", scalar<std::int32_t>(I32::min()), scalar<std::int32_t>(I32::max()));
    add("p_uint32", scalar<std::uint32_t>(4294967295u), scalar<std::uint32_t>(0));
    add("p_int64", scalar<std::int64_t>(std::numeric_limits<std::int64_t>::min()),
        scalar<std::int64_t>(std::numeric_limits<std::int64_t>::max()));
    add("p_uint64", scalar<std::uint64_t>(std::numeric_limits<std::uint64_t>::max()), scalar<std::uint64_t>(0));
    add("p_cdouble", scalar<cdouble>(cdouble(1.5, -2.25)), scalar<cdouble>(cdouble(-0.0, 1e300)));
    add("p_csingle", scalar<csingle>(csingle(0.5f, -0.25f)), scalar<csingle>(csingle(kF32Max, -kF32Tiny)));
    add("p_bool", scalar<bool>(true), scalar<bool>(false));
    add("p_string", str(kUtf8Text), str(""));
    add("p_enum", color(kBlue), color(kMinus));

    add("a_double", array<double>({0.0, -0.0, 1.5, kInf, -kInf, kNaN, 5e-324, 1.7976931348623157e308}), array<double>({2.5}));
    add("a_single", array<float>({kF32Max, -1.5f, kF32Tiny, std::numeric_limits<float>::quiet_NaN()}), array<float>({1.0f, 2.0f}));
    add("a_int8", array<std::int8_t>({-128, -1, 0, 1, 127}), array<std::int8_t>({5}));
    std::vector<std::uint8_t> all_bytes(256);
    for (int i = 0; i < 256; ++i) all_bytes[i] = static_cast<std::uint8_t>(i);
    add("a_uint8", array<std::uint8_t>(all_bytes), array<std::uint8_t>({255, 0}));
    add("a_int16", array<std::int16_t>({-32768, 0, 32767}), array<std::int16_t>({-2}));
    add("a_uint16", array<std::uint16_t>({0, 1, 65535}), array<std::uint16_t>({7}));
    add("a_int32", array<std::int32_t>({I32::min(), 0, I32::max()}), array<std::int32_t>({9, 8}));
    add("a_uint32", array<std::uint32_t>({0, 4294967295u}), array<std::uint32_t>({1}));
    add("a_int64", array<std::int64_t>({std::numeric_limits<std::int64_t>::min(), -1, std::numeric_limits<std::int64_t>::max()}),
        array<std::int64_t>({0}));
    add("a_uint64", array<std::uint64_t>({0, std::numeric_limits<std::uint64_t>::max(), 9223372036854775808ull}),
        array<std::uint64_t>({42}));
    add("a_cdouble", array<cdouble>({cdouble(1, 2), cdouble(-0.0, kInf)}), array<cdouble>({cdouble(0, 0)}));
    add("a_csingle", array<csingle>({csingle(1, -2), csingle(0.5f, 0.25f)}), array<csingle>({csingle(0, 3)}));
    add("a_bool", bools({true, false, false, true}), bools({false}));
    add("a_fixed", array<double>({1.0, 2.0, 3.0}), array<double>({-1.0, -2.0, -3.0}));
    add("a_bounded", array<std::int16_t>({1, 2, 3, 4}), array<std::int16_t>({}));
    add("a_empty", array<std::uint8_t>({}), array<std::uint8_t>({1, 2, 3}));

    add("m_double", fortran<double>({2, 3}, {1, 2, 3, 4, 5, 6}), fortran<double>({1, 1}, {9.5}));
    add("m_fixed", fortran<std::int32_t>({2, 3}, {-1, 2, -3, 4, -5, 6}), fortran<std::int32_t>({2, 3}, {0, 1, 2, 3, 4, 5}));
    std::vector<std::uint8_t> r24(24);
    for (int i = 0; i < 24; ++i) r24[i] = static_cast<std::uint8_t>(i);
    add("m_3d", fortran<std::uint8_t>({2, 3, 4}, r24), fortran<std::uint8_t>({1, 2, 1}, {7, 8}));
    // Python: -3j is complex(-0.0, -3.0)
    add("m_complex", fortran<cdouble>({2, 2}, {cdouble(0, 1), cdouble(2, 0), cdouble(-0.0, -3), cdouble(4, 4)}),
        fortran<cdouble>({1, 3}, {cdouble(0, 0), cdouble(1, 0), cdouble(2, 0)}));
    add("m_bool", Value(MultiDimArray{{3, 2}, NumericArray::from<bool>({true, false, true, true, false, false})}),
        Value(MultiDimArray{{1, 1}, NumericArray::from<bool>({true})}));

    add("s_inner", inner(1), inner(-2, "été", std::vector<double>{}));
    add("s_everything", everything(0), everything(1));
    add("s_null", Value(), inner(99));

    add("pod_scalar", test_pods(1, 0), test_pods(1, 4));
    add("pod_array", test_pods(3, 0), test_pods(0));
    add("pod_fixed", test_pods(2, 10), test_pods(2, 20));
    add("pod_md", test_pods(6, 0, {3, 2}), test_pods(1, 2, {1, 1}));

    add("na_scalar", vec3s(1), vec3s(1, 3));
    add("na_array", vec3s(4), vec3s(0));
    add("na_nested", poses(2), poses(1, 9));
    add("na_md", vec3s(6, 0, {2, 3}), vec3s(2, 0, {2, 1}));

    add("map_int", Value(MapInt32{{{I32::min(), scalar<double>(1.0)}, {-1, scalar<double>(-0.0)}, {0, scalar<double>(kNaN)},
                                   {I32::max(), scalar<double>(5e-324)}}}),
        Value(MapInt32{}));
    add("map_str", Value(MapString{{{"", str("empty key")}, {"key", str("value")}, {"üñî 🤖", str(kUtf8Text)}}}),
        Value(MapString{{{"x", str("")}}}));
    add("map_struct", Value(MapInt32{{{1, inner(1)}, {-7, inner(-7)}}}), Value(MapInt32{{{0, inner(0)}}}));
    add("map_pod", Value(MapString{{{"first", test_pods(1, 1)}, {"second", test_pods(1, 2)}}}), Value(MapString{}));
    add("list_str", list({str("a"), str(""), str(kUtf8Text)}), list({str("only")}));
    add("list_struct", list({inner(1), inner(2), inner(3)}), list({}));
    add("list_arrays", list({array<double>({1.0}), array<double>({}), array<double>({2.0, 3.0})}), list({array<double>({4.0})}));
    add("list_enum", list({color(kRed), color(kGreen), color(kBlue), color(kMinus)}), list({color(kGreen)}));
    add("list_na", list({vec3s(1, 1), vec3s(1, 2)}), list({vec3s(1, 8)}));
    add("map_null", Value(), Value(MapInt32{{{5, scalar<double>(5.5)}}}));
    add("list_empty", list({}), list({str("now"), str("full")}));

    auto cat = varvalue_catalog();
    add("v_any", cat["struct"], cat["int32[*]"]);
    MapString all;
    for (const auto& k : kVarvalueKinds) all.entries.emplace_back(k, cat[k]);
    add("v_map", Value(std::move(all)), Value(MapString{}));
    add("v_list", list({cat["string"], cat["pod[]"], Value(), cat["varvalue{int32}"]}), list({}));
    add("v_null", Value(), cat["string"]);

    add("nolock_value", scalar<std::int32_t>(11), scalar<std::int32_t>(12));
    return p;
}

std::string child_name(const std::string& key) { return "child[" + key + "]"; }
std::string event_text(std::int32_t seq) { return "event " + std::to_string(seq) + " ✓"; }
Value event_data(std::int32_t seq) { return inner(seq, "event", std::vector<double>{seq * 1.5}); }
Value stream_packet(std::int32_t i) { return array<double>({double(i), i * 0.5}); }
Value state_value(std::int32_t seq, const std::string& label) { return inner(seq, label, std::vector<double>{seq * 0.25}); }

Value mem_double_initial() {
    std::vector<double> v(kMemDoubleLen);
    for (std::size_t i = 0; i < v.size(); ++i) v[i] = i * 0.5;
    return array<double>(std::move(v));
}
Value mem_md_initial() {
    std::vector<std::int32_t> v(20);
    for (int i = 0; i < 20; ++i) v[i] = i - 10;
    return fortran<std::int32_t>({4, 5}, std::move(v));
}
Value mem_ro_initial() {
    std::vector<std::uint8_t> v(kMemRoLen);
    for (std::size_t i = 0; i < v.size(); ++i) v[i] = static_cast<std::uint8_t>(i * 3);
    return array<std::uint8_t>(std::move(v));
}

// ------------------------------------------------------------------------------------------------
// Value comparison for property sets: both sides packed with the property type (the canonical wire
// form), maps compared by key whatever their order (Python's deep_equal compares dicts so).

bool same_element(const MessageElement& a, const MessageElement& b) {
    if (a.type != b.type || a.type_name != b.type_name || a.elements.size() != b.elements.size()) return false;
    if (a.name != b.name || a.number != b.number) return false;
    if (a.data.size() != b.data.size() ||
        (a.data.size() && std::memcmp(a.data.data(), b.data.data(), a.data.size()) != 0))
        return false;
    if (a.type == DataTypes::vector_t || a.type == DataTypes::dictionary_t) {
        for (const auto& x : a.elements) {
            bool found = false;
            for (const auto& y : b.elements)
                if (x.name == y.name && x.number == y.number) {
                    found = same_element(x, y);
                    break;
                }
            if (!found) return false;
        }
        return true;
    }
    for (std::size_t i = 0; i < a.elements.size(); ++i)
        if (!same_element(a.elements[i], b.elements[i])) return false;
    return true;
}

// ------------------------------------------------------------------------------------------------
// Generators

class CountUp : public Generator {
public:
    CountUp(struct Interop* owner, std::int64_t start, std::int64_t count) : owner_(owner), next_(start), end_(start + count) {}
    Result<Value> next(std::optional<Value>) override;
    Result<void> close() override;
    Result<void> abort() override;

private:
    struct Interop* owner_;
    std::int64_t next_, end_;
    bool closed_ = false, aborted_ = false;
};

class RunningSum : public Generator {
public:
    explicit RunningSum(struct Interop* owner) : owner_(owner) {}
    Result<Value> next(std::optional<Value> x) override;
    Result<void> close() override;
    Result<void> abort() override;

private:
    struct Interop* owner_;
    double total_ = 0;
    bool done_ = false;
};

class Collect : public Generator {
public:
    explicit Collect(struct Interop* owner) : owner_(owner) {}
    Result<Value> next(std::optional<Value> s) override;
    Result<void> close() override;
    Result<void> abort() override;

private:
    struct Interop* owner_;
    bool done_ = false;
};

// ------------------------------------------------------------------------------------------------
// The service

template <class T>
T must(Result<T> r, const char* what) {
    if (!r) {
        std::cerr << "[interop_service] " << what << ": " << r.error().message << std::endl;
        std::exit(2);
    }
    return std::move(*r);
}
void must(Result<void> r, const char* what) {
    if (!r) {
        std::cerr << "[interop_service] " << what << ": " << r.error().message << std::endl;
        std::exit(2);
    }
}

struct Child {
    std::string key;
    std::int32_t value0 = 0;
    double leaf_x0 = 0;
    std::shared_ptr<ServiceObject> object, leaf;
};

struct Interop {
    std::shared_ptr<const ServiceTypes> types;
    std::shared_ptr<ServiceObject> root;
    std::shared_ptr<ObjectService> service;
    std::shared_ptr<WireMember> w_state, w_both, w_sink;
    std::shared_ptr<CallbackMember> cb_compute, cb_notify;
    std::vector<std::pair<std::string, std::shared_ptr<MemoryMember>>> memories;
    std::map<std::string, std::pair<MessageElement, MessageElement>> ab;  // packed A and B per property
    std::vector<std::pair<std::string, Value>> initial;                   // property -> A
    Child child;
    std::map<std::int32_t, Child> children_int;
    std::map<std::string, Child> children_str;
    std::shared_ptr<ServiceObject> any_leaf;

    std::mutex mutex;
    std::int32_t wo_value = 0;
    std::vector<std::string> collected, generator_log;
    std::optional<Value> both_in;
    Value both_out;
    std::int32_t sink_value = -1;
    std::vector<std::shared_ptr<PipeEndpoint>> stream_eps;
    std::int32_t tick = 0;

    void log_generator(std::string what) {
        std::lock_guard lock(mutex);
        generator_log.push_back(std::move(what));
    }

    Child make_child(const std::string& key, std::int32_t value) {
        Child c;
        c.key = key;
        c.value0 = value;
        c.leaf_x0 = value + 0.5;
        c.object = must(ServiceObject::create(types, qn("Child")), "Child");
        c.leaf = must(ServiceObject::create(types, qn("Leaf")), "Leaf");
        must(c.object->set_property_value("name", str(child_name(key))), "Child.name");
        ServiceObject* obj = c.object.get();
        std::string name = child_name(key);
        must(c.object->set_function("describe",
                                    [obj, name](const SessionRef&, std::vector<Value>) -> Result<Value> {
                                        auto v = obj->property_value("value");
                                        if (!v) return v.take_error();
                                        return str(name + " value=" + std::to_string(*v->as<std::int32_t>()));
                                    }),
             "Child.describe");
        std::weak_ptr<ServiceObject> leaf = c.leaf;
        must(c.object->set_objref("leaf",
                                  [leaf](const SessionRef&, const ObjRefIndex&) -> Result<std::shared_ptr<ServiceObject>> {
                                      return leaf.lock();
                                  }),
             "Child.leaf");
        setup_leaf(*c.leaf);
        return c;
    }

    static void setup_leaf(ServiceObject& leaf) {
        ServiceObject* l = &leaf;
        must(leaf.set_function("scaled",
                               [l](const SessionRef&, std::vector<Value> args) -> Result<Value> {
                                   auto x = l->property_value("x");
                                   if (!x) return x.take_error();
                                   return scalar<double>(*x->as<double>() * *args[0].as<double>());
                               }),
             "Leaf.scaled");
    }

    void reset() {
        for (const auto& [name, a] : initial) must(root->set_property_value(name, a), name.c_str());
        {
            std::lock_guard lock(mutex);
            wo_value = 0;
            collected.clear();
            generator_log.clear();
            both_in.reset();
            both_out = array<double>({0.0});
            sink_value = -1;
        }
        for (auto& [name, mem] : memories) {
            Value v;
            if (name == "mem_double") v = mem_double_initial();
            if (name == "mem_md") v = mem_md_initial();
            if (name == "mem_pod") v = test_pods(kMemPodLen, 30);
            if (name == "mem_pod_md") v = test_pods(6, 40, {2, 3});
            if (name == "mem_na") v = vec3s(kMemNaLen, 50);
            if (name == "mem_na_md") v = vec3s(6, 60, {3, 2});
            if (name == "mem_ro") v = mem_ro_initial();
            must(mem->set_contents(std::move(v)), name.c_str());
        }
        auto reset_child = [](Child& c) {
            must(c.object->set_property_value("value", scalar<std::int32_t>(c.value0)), "child value");
            must(c.leaf->set_property_value("x", scalar<double>(c.leaf_x0)), "leaf x");
        };
        reset_child(child);
        for (auto& [k, c] : children_int) reset_child(c);
        for (auto& [k, c] : children_str) reset_child(c);
        must(any_leaf->set_property_value("x", scalar<double>(-3.5)), "any_obj x");
    }

    void build(std::shared_ptr<const ServiceTypes> t) {
        types = std::move(t);
        root = must(ServiceObject::create(types, qn("Root")), "Root");
        Interop* self = this;

        // properties: A initially; a set must be A or B (compared in packed form)
        const auto& root_def = root->definition();
        for (auto& [name, v] : property_values()) {
            const auto* m = root_def.find_member(name);
            if (!m) {
                std::cerr << "[interop_service] robdef has no property " << name << std::endl;
                std::exit(2);
            }
            auto pa = must(pack_value(v.first, m->type, "value", types->set(), kSvc), name.c_str());
            auto pb = must(pack_value(v.second, m->type, "value", types->set(), kSvc), name.c_str());
            ab[name] = {std::move(pa), std::move(pb)};
            initial.emplace_back(name, v.first);
            const robdef::TypeDefinition* type = &m->type;
            std::string pname = name;
            must(root->set_property_handlers(
                     name, {},
                     [self, pname, type](const SessionRef&, Value value) -> Result<void> {
                         auto packed = pack_value(value, *type, "value", self->types->set(), kSvc);
                         if (!packed) return packed.take_error();
                         const auto& [a, b] = self->ab.at(pname);
                         if (!same_element(*packed, a) && !same_element(*packed, b))
                             return fail(MessageErrorType::InvalidArgument,
                                         "set " + pname + ": value is neither A nor B");
                         return self->root->set_property_value(pname, std::move(value));
                     }),
                 name.c_str());
        }
        must(root->set_property_value("base_name", str(kBaseName)), "base_name");
        must(root->set_property_value("ro_value", scalar<std::int32_t>(kRoValue)), "ro_value");
        must(root->set_property_handlers("wo_value", {},
                                         [self](const SessionRef&, Value v) -> Result<void> {
                                             auto i = v.as<std::int32_t>();
                                             if (!i) return i.take_error();
                                             std::lock_guard lock(self->mutex);
                                             self->wo_value = *i;
                                             return {};
                                         }),
             "wo_value");
        must(root->set_property_handlers("collected",
                                         [self](const SessionRef&) -> Result<Value> {
                                             std::lock_guard lock(self->mutex);
                                             List l;
                                             for (const auto& s : self->collected) l.items.push_back(str(s));
                                             return Value(std::move(l));
                                         }),
             "collected");

        // functions
        auto fn = [&](const char* name, FunctionHandler h) { must(root->set_function(name, std::move(h)), name); };
        fn("reset", [self](const SessionRef&, std::vector<Value>) -> Result<Value> {
            self->reset();
            return Value();
        });
        fn("add", [](const SessionRef&, std::vector<Value> a) -> Result<Value> {
            std::int64_t r = std::int64_t(*a[0].as<std::int32_t>()) + *a[1].as<std::int32_t>();
            if (r < std::numeric_limits<std::int32_t>::min() || r > std::numeric_limits<std::int32_t>::max())
                return fail(MessageErrorType::OutOfRange, "add overflows int32");
            return scalar<std::int32_t>(static_cast<std::int32_t>(r));
        });
        fn("mix", [](const SessionRef&, std::vector<Value> a) -> Result<Value> {
            Value s = everything(0);
            auto& st = *s.get_if<Structure>();
            st.set("f_double", a[0]);
            st.set("f_string", a[1]);
            st.set("f_inner", a[2]);
            st.set("f_pod", a[3]);
            st.set("f_vec", a[4]);
            st.set("f_any", a[5]);
            st.set("f_enum", a[6]);
            List strings;
            if (auto* h = a[7].get_if<List>())
                for (const auto& x : h->items) strings.items.push_back(str(std::to_string(*x.as<std::int32_t>())));
            st.set("f_strings", Value(std::move(strings)));
            return s;
        });
        fn("make_inner", [](const SessionRef&, std::vector<Value> a) -> Result<Value> {
            Structure s;
            s.type_name = qn("Inner");
            s.set("id", a[0]);
            s.set("label", a[1]);
            s.set("values", a[2]);
            return Value(std::move(s));
        });
        fn("echo", [](const SessionRef&, std::vector<Value> a) -> Result<Value> { return std::move(a[0]); });
        fn("catalog", [](const SessionRef&, std::vector<Value> a) -> Result<Value> {
            static const auto cat = varvalue_catalog();
            const std::string kind = *a[0].as<std::string>();
            auto it = cat.find(kind);
            if (it == cat.end()) return fail(MessageErrorType::InvalidArgument, "unknown varvalue kind '" + kind + "'");
            return it->second;
        });
        fn("throw_user", [self](const SessionRef&, std::vector<Value> a) -> Result<Value> {
            return fail(self->root->user_error("InteropError", *a[0].as<std::string>()));
        });
        fn("throw_standard", [](const SessionRef&, std::vector<Value>) -> Result<Value> {
            return fail(MessageErrorType::InvalidArgument, "standard error from throw_standard");
        });
        fn("wo_value_last", [self](const SessionRef&, std::vector<Value>) -> Result<Value> {
            std::lock_guard lock(self->mutex);
            return scalar<std::int32_t>(self->wo_value);
        });
        fn("generator_log", [self](const SessionRef&, std::vector<Value>) -> Result<Value> {
            std::lock_guard lock(self->mutex);
            List l;
            for (const auto& s : self->generator_log) l.items.push_back(str(s));
            return Value(std::move(l));
        });

        // generators
        must(root->set_generator_function("count_up",
                                          [self](const SessionRef&, std::vector<Value> a) -> Result<std::shared_ptr<Generator>> {
                                              return std::shared_ptr<Generator>(std::make_shared<CountUp>(
                                                  self, *a[0].as<std::int32_t>(), *a[1].as<std::int32_t>()));
                                          }),
             "count_up");
        must(root->set_generator_function("running_sum",
                                          [self](const SessionRef&, std::vector<Value>) -> Result<std::shared_ptr<Generator>> {
                                              return std::shared_ptr<Generator>(std::make_shared<RunningSum>(self));
                                          }),
             "running_sum");
        must(root->set_generator_function("collect",
                                          [self](const SessionRef&, std::vector<Value>) -> Result<std::shared_ptr<Generator>> {
                                              return std::shared_ptr<Generator>(std::make_shared<Collect>(self));
                                          }),
             "collect");

        // events
        fn("fire_events", [self](const SessionRef&, std::vector<Value> a) -> Result<Value> {
            const std::int32_t count = *a[0].as<std::int32_t>();
            for (std::int32_t seq = 0; seq < count; ++seq)
                if (auto r = self->root->fire_event("ev_values", {scalar<std::int32_t>(seq), str(event_text(seq)), event_data(seq)}); !r)
                    return r.take_error();
            if (auto r = self->root->fire_event("ev_empty", {}); !r) return r.take_error();
            return Value();
        });

        // objrefs
        child = make_child("plain", 1);
        for (auto k : kChildIntKeys) children_int.emplace(k, make_child(std::to_string(k), 100 + k));
        for (std::size_t i = 0; i < kChildStrKeys.size(); ++i)
            children_str.emplace(kChildStrKeys[i], make_child(kChildStrKeys[i], 200 + static_cast<std::int32_t>(i)));
        any_leaf = must(ServiceObject::create(types, qn("Leaf")), "any_obj");
        setup_leaf(*any_leaf);
        must(root->set_objref("child", [self](const SessionRef&, const ObjRefIndex&) -> Result<std::shared_ptr<ServiceObject>> {
                 return self->child.object;
             }),
             "child");
        must(root->set_objref("child_by_int",
                              [self](const SessionRef&, const ObjRefIndex& i) -> Result<std::shared_ptr<ServiceObject>> {
                                  const std::int32_t k = std::get<std::int32_t>(i);
                                  auto it = self->children_int.find(k);
                                  if (it == self->children_int.end())
                                      return fail(MessageErrorType::ObjectNotFound, "no child_by_int[" + std::to_string(k) + "]");
                                  return it->second.object;
                              }),
             "child_by_int");
        must(root->set_objref("child_by_name",
                              [self](const SessionRef&, const ObjRefIndex& i) -> Result<std::shared_ptr<ServiceObject>> {
                                  const std::string& k = std::get<std::string>(i);
                                  auto it = self->children_str.find(k);
                                  if (it == self->children_str.end())
                                      return fail(MessageErrorType::ObjectNotFound, "no child_by_name[" + k + "]");
                                  return it->second.object;
                              }),
             "child_by_name");
        must(root->set_objref("any_obj", [self](const SessionRef&, const ObjRefIndex&) -> Result<std::shared_ptr<ServiceObject>> {
                 return self->any_leaf;
             }),
             "any_obj");
        fn("release_child", [self](const SessionRef&, std::vector<Value> a) -> Result<Value> {
            const std::int32_t index = *a[0].as<std::int32_t>();
            auto it = self->children_int.find(index);
            if (it == self->children_int.end())
                return fail(MessageErrorType::InvalidArgument, "no child_by_int[" + std::to_string(index) + "]");
            auto paths = it->second.object->paths();
            if (paths.empty())
                return fail(MessageErrorType::InvalidOperation,
                            "child_by_int[" + std::to_string(index) + "] was never requested");
            for (const auto& p : paths)
                if (auto r = self->service_release(p); !r) return r.take_error();
            return Value();
        });

        // pipes
        for (const char* name : {"p_echo", "p_unreliable"}) {
            auto p = must(root->pipe(name), name);
            p->on_packet([](const std::shared_ptr<PipeEndpoint>& ep, Value packet) { (void)ep->send(packet); });
        }
        auto stream = must(root->pipe("p_stream"), "p_stream");
        stream->on_connect([self](const std::shared_ptr<PipeEndpoint>& ep) -> Result<void> {
            std::lock_guard lock(self->mutex);
            self->stream_eps.push_back(ep);
            return {};
        });
        stream->on_close([self](const std::shared_ptr<PipeEndpoint>& ep) {
            std::lock_guard lock(self->mutex);
            std::erase(self->stream_eps, ep);
        });
        fn("send_stream", [self](const SessionRef&, std::vector<Value> a) -> Result<Value> {
            const std::int32_t count = *a[0].as<std::int32_t>();
            std::vector<std::shared_ptr<PipeEndpoint>> eps;
            {
                std::lock_guard lock(self->mutex);
                eps = self->stream_eps;
            }
            for (const auto& ep : eps)
                for (std::int32_t i = 0; i < count; ++i)
                    if (auto r = ep->send(stream_packet(i)); !r) return r.take_error();
            return Value();
        });
        fn("close_stream", [self](const SessionRef&, std::vector<Value>) -> Result<Value> {
            std::vector<std::shared_ptr<PipeEndpoint>> eps;
            {
                std::lock_guard lock(self->mutex);
                eps.swap(self->stream_eps);
            }
            for (const auto& ep : eps) ep->close();
            return Value();
        });

        // callbacks
        cb_compute = must(root->callback("cb_compute"), "cb_compute");
        cb_notify = must(root->callback("cb_notify"), "cb_notify");
        must(root->set_async_function("call_callbacks",
                                      [self](const SessionRef& session, std::vector<Value> a, Completion done) {
                                          const double x = *a[0].as<double>();
                                          self->cb_notify->call(
                                              session, {inner(77, "notify")},
                                              [self, session, x, done](Result<Value> r) {
                                                  if (!r) {
                                                      done(r.take_error());
                                                      return;
                                                  }
                                                  self->cb_compute->call(session, {scalar<double>(x), str(kCallbackLabel)},
                                                                         [done](Result<Value> r2) {
                                                                             if (!r2) {
                                                                                 done(r2.take_error());
                                                                                 return;
                                                                             }
                                                                             auto v = r2->as<double>();
                                                                             if (!v) {
                                                                                 done(v.take_error());
                                                                                 return;
                                                                             }
                                                                             done(scalar<double>(*v + 1.0));
                                                                         });
                                              });
                                      }),
             "call_callbacks");

        // wires
        w_state = must(root->wire("w_state"), "w_state");
        must(w_state->set_out_value(state_value(0, "initial")), "w_state initial");
        fn("update_state", [self](const SessionRef&, std::vector<Value> a) -> Result<Value> {
            if (auto r = self->w_state->set_out_value(state_value(*a[0].as<std::int32_t>(), "demand")); !r) return r.take_error();
            return Value();
        });
        w_both = must(root->wire("w_both"), "w_both");
        w_both->on_value([self](const std::shared_ptr<WireConnection>& conn, const Value& v, TimeSpec) {
            if (!conn) return;
            const auto* a = v.get_if<NumericArray>();
            if (!a) return;
            std::vector<double> rev(a->size());
            auto in = a->view<double>();
            for (std::size_t i = 0; i < rev.size(); ++i) rev[i] = in[rev.size() - 1 - i];
            Value r = array<double>(std::move(rev));
            {
                std::lock_guard lock(self->mutex);
                self->both_in = v;
                self->both_out = r;
            }
            (void)conn->set_out_value(r);
        });
        w_both->set_peek_in_handler([self](const SessionRef&) -> Result<TimedValue> {
            std::lock_guard lock(self->mutex);
            return TimedValue{self->both_out, wall_clock_timespec()};
        });
        w_both->set_peek_out_handler([self](const SessionRef&) -> Result<TimedValue> {
            std::lock_guard lock(self->mutex);
            if (!self->both_in) return fail(MessageErrorType::ValueNotSet, "w_both has no value from a client yet");
            return TimedValue{*self->both_in, wall_clock_timespec()};
        });
        w_both->set_poke_handler([self](const SessionRef&, Value v, TimeSpec) -> Result<void> {
            std::lock_guard lock(self->mutex);
            self->both_in = std::move(v);
            return {};
        });
        w_sink = must(root->wire("w_sink"), "w_sink");
        w_sink->on_value([self](const std::shared_ptr<WireConnection>&, const Value& v, TimeSpec) {
            auto i = v.as<std::int32_t>();
            if (!i) return;
            std::lock_guard lock(self->mutex);
            self->sink_value = *i;
        });
        fn("w_sink_value", [self](const SessionRef&, std::vector<Value>) -> Result<Value> {
            std::lock_guard lock(self->mutex);
            return scalar<std::int32_t>(self->sink_value);
        });

        // memories
        for (const char* name : {"mem_double", "mem_md", "mem_pod", "mem_pod_md", "mem_na", "mem_na_md", "mem_ro"})
            memories.emplace_back(name, must(root->memory(name), name));

        reset();
    }

    Result<void> service_release(const std::string& path) { return service->release_path(path); }

    void tick_state() {
        std::int32_t t;
        {
            std::lock_guard lock(mutex);
            t = ++tick;
        }
        if (auto r = w_state->set_out_value(state_value(t, "tick")); !r)
            std::cerr << "[interop_service] tick failed: " << r.error().message << std::endl;
    }
};

Result<Value> CountUp::next(std::optional<Value>) {
    if (aborted_) return fail(MessageErrorType::OperationAborted, "count_up aborted");
    if (closed_ || next_ >= end_) return fail(MessageErrorType::StopIteration, "count_up done");
    return scalar<std::int32_t>(static_cast<std::int32_t>(next_++));
}
Result<void> CountUp::close() {
    closed_ = true;
    owner_->log_generator("count_up:close");
    return {};
}
Result<void> CountUp::abort() {
    aborted_ = true;
    owner_->log_generator("count_up:abort");
    return {};
}

Result<Value> RunningSum::next(std::optional<Value> x) {
    if (done_) return fail(MessageErrorType::StopIteration, "running_sum closed");
    auto v = x ? x->as<double>() : Result<double>(fail(MessageErrorType::MessageElementNotFound, "no parameter"));
    if (!v) return v.take_error();
    total_ += *v;
    return scalar<double>(total_);
}
Result<void> RunningSum::close() {
    done_ = true;
    owner_->log_generator("running_sum:close");
    return {};
}
Result<void> RunningSum::abort() {
    done_ = true;
    owner_->log_generator("running_sum:abort");
    return {};
}

Result<Value> Collect::next(std::optional<Value> s) {
    if (done_) return fail(MessageErrorType::StopIteration, "collect closed");
    auto v = s ? s->as<std::string>() : Result<std::string>(fail(MessageErrorType::MessageElementNotFound, "no parameter"));
    if (!v) return v.take_error();
    std::lock_guard lock(owner_->mutex);
    owner_->collected.push_back(std::move(*v));
    return Value();
}
Result<void> Collect::close() {
    done_ = true;
    owner_->log_generator("collect:close");
    return {};
}
Result<void> Collect::abort() {
    done_ = true;
    owner_->log_generator("collect:abort");
    return {};
}

std::string json_string(const std::string& s) {
    std::string out = "\"";
    for (char c : s) {
        if (c == '"' || c == '\\') out += '\\';
        out += c;
    }
    return out + "\"";
}

volatile std::sig_atomic_t g_stop = 0;

[[noreturn]] void usage(const char* argv0) {
    std::cerr << "usage: " << argv0
              << " [--port N] [--websocket] [--disable-message4] [--enable-stringtable] [--heartbeat S]"
                 " [--listen-all] [--max-lifetime S] [--robdef PATH] [--local-name NAME | --local] [--users FILE]\n";
    std::exit(2);
}

}  // namespace

int main(int argc, char** argv) {
    std::uint16_t port = 0;
    bool disable_message4 = false, enable_stringtable = false, listen_all = false, websocket = false;
    std::optional<double> heartbeat;
    double max_lifetime = 0;
    std::string robdef_path = RR_INTEROP_ROBDEF;
    std::optional<std::string> local_name;
    bool local_by_id = false;
    std::optional<std::string> users_path;
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        auto value = [&]() -> std::string {
            if (i + 1 >= argc) usage(argv[0]);
            return argv[++i];
        };
        if (a == "--port") port = static_cast<std::uint16_t>(std::stoi(value()));
        else if (a == "--websocket") websocket = true;
        else if (a == "--disable-message4") disable_message4 = true;
        else if (a == "--enable-stringtable") enable_stringtable = true;
        else if (a == "--heartbeat") heartbeat = std::stod(value());
        else if (a == "--listen-all") listen_all = true;
        else if (a == "--max-lifetime") max_lifetime = std::stod(value());
        else if (a == "--robdef") robdef_path = value();
        else if (a == "--local-name") local_name = value();
        else if (a == "--local") local_by_id = true;
        else if (a == "--users") users_path = value();
        else usage(argv[0]);
    }

    // SIGTERM / SIGINT only set a flag (whichever thread takes them); the main thread polls it.
    struct sigaction sa {};
    sa.sa_handler = [](int) { g_stop = 1; };
    sigemptyset(&sa.sa_mask);
    sigaction(SIGTERM, &sa, nullptr);
    sigaction(SIGINT, &sa, nullptr);

    std::ifstream in(robdef_path);
    if (!in) {
        std::cerr << "[interop_service] cannot read " << robdef_path << std::endl;
        return 2;
    }
    std::stringstream text;
    text << in.rdbuf();
    auto types = must(ServiceTypes::create({text.str()}), "robdef");

    NodeOptions options;
    options.node_name = "interop_service";
    std::optional<server::local::NodeNameReservation> reservation;
    if (local_name) {
        auto r = server::local::reserve_node_name(server::local::default_node_directories(), *local_name);
        if (!r) {
            std::cerr << "[interop_service] rr+local: " << r.error().message << std::endl;
            return 3;
        }
        options.node_name = *local_name;
        options.node_id = r->node_id;
        reservation = std::move(*r);
    } else if (local_by_id) {
        options.node_name.clear();
    }
    options.server.stream.enable_message4 = !disable_message4;
    options.server.stream.enable_string_table = enable_stringtable;
    if (heartbeat) options.server.stream.heartbeat_period = std::chrono::milliseconds(static_cast<long>(*heartbeat * 1000));

    auto interop = std::make_unique<Interop>();
    interop->build(types);
    interop->service = must(ObjectService::create("interop", interop->root), "service");
    MapString attributes;
    attributes.entries.emplace_back("purpose", str("interop test ✓"));
    attributes.entries.emplace_back("version", array<std::int32_t>({1, 0}));
    must(interop->service->set_attributes(std::move(attributes)), "attributes");
    if (users_path) interop->service->set_users(must(PasswordTable::load_file(*users_path), "--users"));

    auto node = Node::create(options);
    must(node->register_service(interop->service), "register");
    std::shared_ptr<http::HttpServer> http_server;  // kept for the whole run: the listener holds it weakly
    TcpListenerOptions tcp;
    if (websocket) {
        // RR over WebSocket on the same port; non-browser clients send no Origin and are let in.
        http_server = std::make_shared<http::HttpServer>(node, http::HttpOptions{});
        tcp.http = http::http_handler(http_server);
    }
    const std::uint16_t bound = must(listen_tcp(node, listen_all ? "0.0.0.0" : "127.0.0.1", port, std::move(tcp)), "listen");
    std::shared_ptr<server::local::LocalListener> local_listener;
    if (local_name || local_by_id) {
        auto l = server::local::listen_local(node, {}, std::move(reservation));
        if (!l) {
            std::cerr << "[interop_service] rr+local: " << l.error().message << std::endl;
            node->shutdown();
            return 3;
        }
        local_listener = *l;
    }

    std::mutex tick_mutex;
    std::condition_variable tick_cv;
    bool stopping = false;
    std::thread ticker([&] {
        std::unique_lock lock(tick_mutex);
        while (!tick_cv.wait_for(lock, kStatePeriod, [&] { return stopping; })) {
            lock.unlock();
            interop->tick_state();
            lock.lock();
        }
    });

    std::cout << "{\"url\": " << json_string("rr+tcp://127.0.0.1:" + std::to_string(bound) + "/?service=interop")
              << ", \"port\": " << bound << ", \"nodeid\": " << json_string(node->node_id().to_braced_string())
              << ", \"nodename\": " << json_string(node->node_name()) << ", \"message4\": " << (disable_message4 ? "false" : "true")
              << ", \"stringtable\": " << (enable_stringtable ? "true" : "false");
    if (websocket) std::cout << ", \"ws_url\": " << json_string("rr+ws://127.0.0.1:" + std::to_string(bound) + "/?service=interop");
    if (local_listener) {
        if (local_name) std::cout << ", \"local_url\": " << json_string("rr+local:///?nodename=" + *local_name + "&service=interop");
        std::cout << ", \"local_id_url\": " << json_string("rr+local:///?nodeid=" + node->node_id().to_string() + "&service=interop")
                  << ", \"local_socket\": " << json_string(local_listener->socket_path());
    }
    std::cout << "}" << std::endl;

    const auto started = std::chrono::steady_clock::now();
    while (!g_stop) {
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
        if (max_lifetime > 0 &&
            std::chrono::steady_clock::now() - started > std::chrono::duration<double>(max_lifetime)) {
            std::cerr << "[interop_service] max lifetime reached" << std::endl;
            break;
        }
    }

    {
        std::lock_guard lock(tick_mutex);
        stopping = true;
    }
    tick_cv.notify_all();
    ticker.join();
    if (local_listener) local_listener->close();
    node->shutdown();
    interop->service->shutdown();
    local_listener.reset();
    node.reset();
    interop.reset();
    return 0;
}
