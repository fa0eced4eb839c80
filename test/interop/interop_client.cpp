// rr_interop_client: OUR typed client (server/client/client.hpp) against a service implementing
// robdef/experimental.interop_test.robdef — the C++ counterpart of official_client.py, with the same
// values (interop_values.py, written out here in C++) and the same checks, section by section.
// With --reynard it instead exercises Reynard the Robot (reynard_official_client.py's behaviours).
//
// Prints one JSON summary line on stdout; exit status 0 = every check passed, 1 = a check failed,
// 2 = could not connect, 3 = overall timeout.
//
// Usage:
//   rr_interop_client URL [--disable-message4] [--timeout S] [--idle S] [--verbose] [--only SECTION,...]
//   rr_interop_client --reynard URL [--timeout S] [--verbose] [--chat]
// With --chat (Reynard), the client prints a line `CHAT <json string>` on stdout when it is ready for
// a web-UI chat message with that text (the orchestrator, our_client_interop.py, sends it with a
// socket.io client) and then expects the `new_message` event carrying it.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <iostream>
#include <limits>
#include <mutex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/value/pack_value.hpp"
#include "core/value/var_type.hpp"
#include "server/client/client.hpp"

using namespace rr;
using rr::client::Client;
using rr::client::ObjectProxy;
using namespace std::chrono_literals;

namespace {

// =====================================================================================================
// Values (interop_values.py)

const std::string kSvc = "experimental.interop_test";
std::string qn(std::string_view s) { return kSvc + "." + std::string(s); }

const std::string UTF8_TEXT = "Gr\u00fc\u00dfe, \u4e16\u754c! \U0001F916 \"quoted\" \\ tab\t newline\n end";
const float F32_MAX = std::numeric_limits<float>::max();
const float F32_TINY = std::numeric_limits<float>::denorm_min();
const double F64_MAX = std::numeric_limits<double>::max();
const double F64_TINY = std::numeric_limits<double>::denorm_min();
const double INF = std::numeric_limits<double>::infinity();
const double NaN = std::numeric_limits<double>::quiet_NaN();
const std::string BASE_NAME = "interop root";
constexpr std::int32_t RO_VALUE = 17;
const std::string CALLBACK_LABEL = "\u03bb-label";

enum Color : std::int32_t { red = 0, green = 1, blue = 16, minus = -5 };

template <Numeric T>
Value S(T v) {
    return Value::scalar<T>(v);
}
template <Numeric T>
Value A(std::initializer_list<T> v) {
    return Value(NumericArray::from<T>(v));
}
template <Numeric T>
Value Av(const std::vector<T>& v) {
    return Value(NumericArray::from<T>(std::span<const T>(v)));
}
template <Numeric T>
Value MD(std::vector<std::uint32_t> dims, std::initializer_list<T> flat) {
    return Value(MultiDimArray{std::move(dims), NumericArray::from<T>(flat)});
}
template <Numeric T>
Value MDv(std::vector<std::uint32_t> dims, const std::vector<T>& flat) {
    return Value(MultiDimArray{std::move(dims), NumericArray::from<T>(std::span<const T>(flat))});
}
Value Str(std::string s) { return Value(std::move(s)); }
Value color(std::int32_t v) { return Value(Enum{qn("Color"), v}); }
Value list(std::vector<Value> items) { return Value(List{std::move(items)}); }
Value map_int(std::vector<std::pair<std::int32_t, Value>> e) { return Value(MapInt32{std::move(e)}); }
Value map_str(std::vector<std::pair<std::string, Value>> e) { return Value(MapString{std::move(e)}); }

Value inner(std::int32_t i, std::optional<std::string> label = std::nullopt,
            std::optional<std::vector<double>> values = std::nullopt) {
    std::string l = label ? *label : "inner " + std::to_string(i) + " \u00e9";
    std::vector<double> v = values ? *values : std::vector<double>{double(i), i + 0.5, double(-i)};
    Structure s{qn("Inner"), {}};
    s.set("id", S<std::int32_t>(i));
    s.set("label", Str(std::move(l)));
    s.set("values", Av<double>(v));
    return Value(std::move(s));
}

Value pod_inners(std::vector<std::pair<std::int16_t, std::vector<double>>> items) {
    PodArray p(qn("PodInner"), {"a", "b"});
    for (auto& [a, b] : items) (void)p.push_back({S<std::int16_t>(a), Av<double>(b)});
    return Value(std::move(p));
}

Value vec3_item(double x, double y, double z) { return Value(NamedArray{qn("Vec3"), NumericArray::from<double>({x, y, z}), {}}); }

std::vector<Value> test_pod_item(int s) {
    std::vector<std::uint8_t> bounded;
    for (int j = 0; j < (s % 6) + 1; ++j) bounded.push_back(static_cast<std::uint8_t>((s * 7 + j) % 256));
    return {S<double>(1.25 * (s + 1)),
            A<std::int32_t>({s, -s, 2147483647, std::numeric_limits<std::int32_t>::min()}),
            Av<std::uint8_t>(bounded),
            pod_inners({{static_cast<std::int16_t>(-32768 + s), {0.5, -0.5, double(s)}}}),
            pod_inners({{static_cast<std::int16_t>(s), {0.0, double(s), -1.0}},
                        {static_cast<std::int16_t>(100 + s), {1.0, double(1 + s), -1.0}}}),
            vec3_item(1.0 + s, -2.0, 0.125),
            S<cdouble>(cdouble(s, -0.75)),
            // numpy [[1, 2], [3, 4+s]] travels flattened in Fortran order (PythonTypeSupport.cpp)
            MD<double>({2, 2}, {1.0, 3.0, 2.0, 4.0 + s})};
}

/// `n` TestPod records with seeds seed, seed+1, …; `dims` for a multi-dim pod array.
Value test_pods(int n, int seed = 0, std::vector<std::uint32_t> dims = {}) {
    PodArray p(qn("TestPod"), {"x", "arr", "bounded", "inner", "inners", "vec", "c", "md"});
    for (int k = 0; k < n; ++k) (void)p.push_back(test_pod_item(seed + k));
    p.dims = std::move(dims);
    return Value(std::move(p));
}

Value pods_of_seeds(const std::vector<int>& seeds, std::vector<std::uint32_t> dims = {}) {
    PodArray p(qn("TestPod"), {"x", "arr", "bounded", "inner", "inners", "vec", "c", "md"});
    for (int s : seeds) (void)p.push_back(test_pod_item(s));
    p.dims = std::move(dims);
    return Value(std::move(p));
}

std::vector<double> vec3_flat(int s) { return {s + 0.5, double(-s), 1e-300 * (s + 1)}; }

Value vec3s_of_seeds(const std::vector<int>& seeds, std::vector<std::uint32_t> dims = {}) {
    std::vector<double> flat;
    for (int s : seeds)
        for (double d : vec3_flat(s)) flat.push_back(d);
    return Value(NamedArray{qn("Vec3"), NumericArray::from<double>(std::span<const double>(flat)), std::move(dims)});
}

Value vec3s(int n, int seed = 0, std::vector<std::uint32_t> dims = {}) {
    std::vector<int> seeds;
    for (int k = 0; k < n; ++k) seeds.push_back(seed + k);
    return vec3s_of_seeds(seeds, std::move(dims));
}

Value poses(int n, int seed = 0) {
    std::vector<double> flat;
    for (int k = 0; k < n; ++k) {
        int s = seed + k;
        for (double d : {double(s), s * 2.0, double(-s), 1.0, 0.0, 0.0, s * 0.25}) flat.push_back(d);
    }
    return Value(NamedArray{qn("Pose"), NumericArray::from<double>(std::span<const double>(flat)), {}});
}

Value everything(int v, int depth = 0) {
    Structure s{qn("Everything"), {}};
    s.set("f_double", S<double>(v == 0 ? -F64_MAX : F64_TINY));
    s.set("f_single", S<float>(v == 0 ? F32_MAX : F32_TINY));
    s.set("f_int8", S<std::int8_t>(v == 0 ? -128 : 127));
    s.set("f_uint8", S<std::uint8_t>(v == 0 ? 255 : 0));
    s.set("f_int16", S<std::int16_t>(v == 0 ? -32768 : 32767));
    s.set("f_uint16", S<std::uint16_t>(v == 0 ? 65535 : 1));
    s.set("f_int32", S<std::int32_t>(v == 0 ? std::numeric_limits<std::int32_t>::min() : 2147483647));
    s.set("f_uint32", S<std::uint32_t>(v == 0 ? 4294967295u : 2u));
    s.set("f_int64", S<std::int64_t>(v == 0 ? std::numeric_limits<std::int64_t>::min() : std::numeric_limits<std::int64_t>::max()));
    s.set("f_uint64", S<std::uint64_t>(v == 0 ? std::numeric_limits<std::uint64_t>::max() : 3u));
    s.set("f_cdouble", S<cdouble>(v == 0 ? cdouble(1.5, -2.25) : cdouble(-0.0, 1e300)));
    s.set("f_csingle", S<csingle>(v == 0 ? csingle(0.5f, -0.25f) : csingle(F32_MAX, F32_TINY)));
    s.set("f_bool", S<bool>(v == 0));
    s.set("f_string", Str(v == 0 ? UTF8_TEXT : ""));
    s.set("f_enum", color(v == 0 ? blue : minus));
    s.set("f_array", A<double>({1.0, 2.0, 3.5 + v}));
    s.set("f_fixed", A<double>({0.25, -0.25, 1e10 * (v + 1)}));
    std::vector<std::int16_t> b = {1, -1, 300};
    b.resize(3 - v);
    s.set("f_bounded", Av<std::int16_t>(b));
    s.set("f_md", MD<double>({2, 3}, {1, 2, 3, 4, 5, 6.0 + v}));
    s.set("f_inner", inner(10 + v));
    s.set("f_inner_null", Value());
    s.set("f_inner_list", v == 0 ? list({inner(1), inner(2, std::string(""))}) : list({}));
    s.set("f_inner_by_int", map_int({{-5, inner(5)}, {0, inner(0)}, {2147483647, inner(7)}}));
    s.set("f_inner_by_name", v == 0 ? map_str({{"a", inner(1)}, {"\u00fc\u00f1\u00ee", inner(2)}}) : map_str({}));
    s.set("f_strings", v == 0 ? list({Str("one"), Str(""), Str("\u4e09")}) : Value());
    s.set("f_pod", test_pods(1, v));
    s.set("f_vec", vec3s(1, v));
    s.set("f_vecs", vec3s(3 - v, 5));
    s.set("f_any", v == 0 ? A<std::int32_t>({1, 2, 3}) : Str("text"));
    s.set("f_any_null", Value());
    s.set("f_self", depth == 0 ? everything(v, depth + 1) : Value());
    return Value(std::move(s));
}

// kind -> (sent, expected back)
std::vector<std::pair<std::string, std::pair<Value, Value>>> varvalue_catalog() {
    std::vector<std::pair<std::string, std::pair<Value, Value>>> cat;
    auto same = [&](std::string kind, Value v) { cat.push_back({std::move(kind), {v, v}}); };
    same("double[]", A<double>({0.0, -0.0, 1.5, INF, -INF, NaN, F64_TINY}));
    same("single[]", A<float>({F32_MAX, -1.5f, F32_TINY}));
    same("int8[]", A<std::int8_t>({-128, 0, 127}));
    same("uint8[]", A<std::uint8_t>({0, 1, 255}));
    same("int16[]", A<std::int16_t>({-32768, 32767}));
    same("uint16[]", A<std::uint16_t>({0, 65535}));
    same("int32[]", A<std::int32_t>({std::numeric_limits<std::int32_t>::min(), 2147483647}));
    same("uint32[]", A<std::uint32_t>({0, 4294967295u}));
    same("int64[]", A<std::int64_t>({std::numeric_limits<std::int64_t>::min(), std::numeric_limits<std::int64_t>::max()}));
    same("uint64[]", A<std::uint64_t>({0, std::numeric_limits<std::uint64_t>::max()}));
    same("cdouble[]", A<cdouble>({cdouble(1, 2), cdouble(-0.5, -0.25)}));
    same("csingle[]", A<csingle>({csingle(1, 2), csingle(-0.5f, -0.25f)}));
    same("bool[]", A<bool>({true, false, true}));
    same("empty double[]", Value(NumericArray(DataTypes::double_t)));
    same("double scalar", S<double>(3.25));  // comes back as a 1-item double[] (the same Value here)
    same("string", Str(UTF8_TEXT));
    same("empty string", Str(""));
    same("double[*]", MD<double>({2, 3}, {1, 2, 3, 4, 5, 6}));
    same("int32[*]", MD<std::int32_t>({2, 2, 2}, {0, 1, 2, 3, 4, 5, 6, 7}));
    same("struct", inner(3));
    same("struct everything", everything(0));
    same("pod[]", test_pods(2, 3));
    same("pod[*]", test_pods(6, 1, {2, 3}));
    same("namedarray[]", vec3s(2));
    same("namedarray[*]", vec3s(4, 0, {2, 2}));
    same("varvalue{list}", list({Str("a"), A<std::int32_t>({1}), Value()}));
    same("varvalue{int32}", map_int({{-1, Str("minus one")}, {2147483647, A<double>({2.0})}}));
    same("varvalue{string}", map_str({{"k", Str("v")}, {"\u00fc", A<std::uint8_t>({7})}}));
    same("string{list}", list({Str("x"), Str("\u00ff")}));
    same("double{int32}", map_int({{3, S<double>(1.5)}, {-4, S<double>(2.5)}}));
    same("nested", map_str({{"list", list({map_str({{"deep", inner(9)}})})}}));
    same("null", Value());
    return cat;
}

const Value& catalog_back(const std::vector<std::pair<std::string, std::pair<Value, Value>>>& cat, std::string_view k) {
    for (const auto& [kind, v] : cat)
        if (kind == k) return v.second;
    throw std::logic_error("no catalogue kind " + std::string(k));
}

std::vector<std::pair<std::string, std::pair<Value, Value>>> property_values() {
    std::vector<std::pair<std::string, std::pair<Value, Value>>> P;
    auto add = [&](std::string name, Value a, Value b) { P.push_back({std::move(name), {std::move(a), std::move(b)}}); };
    using i8 = std::int8_t;
    using u8 = std::uint8_t;
    using i16 = std::int16_t;
    using u16 = std::uint16_t;
    using i32 = std::int32_t;
    using u32 = std::uint32_t;
    using i64 = std::int64_t;
    using u64 = std::uint64_t;
    add("p_double", S<double>(-F64_MAX), S<double>(F64_TINY));
    add("p_single", S<float>(F32_MAX), S<float>(-F32_TINY));
    add("p_int8", S<i8>(-128), S<i8>(127));
    add("p_uint8", S<u8>(255), S<u8>(0));
    add("p_int16", S<i16>(-32768), S<i16>(32767));
    add("p_uint16", S<u16>(65535), S<u16>(0));
    add("p_int32", S<i32>(std::numeric_limits<i32>::min()), S<i32>(2147483647));
    add("p_uint32", S<u32>(4294967295u), S<u32>(0));
    add("p_int64", S<i64>(std::numeric_limits<i64>::min()), S<i64>(std::numeric_limits<i64>::max()));
    add("p_uint64", S<u64>(std::numeric_limits<u64>::max()), S<u64>(0));
    add("p_cdouble", S<cdouble>(cdouble(1.5, -2.25)), S<cdouble>(cdouble(-0.0, 1e300)));
    add("p_csingle", S<csingle>(csingle(0.5f, -0.25f)), S<csingle>(csingle(F32_MAX, -F32_TINY)));
    add("p_bool", S<bool>(true), S<bool>(false));
    add("p_string", Str(UTF8_TEXT), Str(""));
    add("p_enum", color(blue), color(minus));

    add("a_double", A<double>({0.0, -0.0, 1.5, INF, -INF, NaN, F64_TINY, F64_MAX}), A<double>({2.5}));
    add("a_single", A<float>({F32_MAX, -1.5f, F32_TINY, std::numeric_limits<float>::quiet_NaN()}), A<float>({1.0f, 2.0f}));
    add("a_int8", A<i8>({-128, -1, 0, 1, 127}), A<i8>({5}));
    std::vector<u8> all(256);
    for (int i = 0; i < 256; ++i) all[i] = static_cast<u8>(i);
    add("a_uint8", Av<u8>(all), A<u8>({255, 0}));
    add("a_int16", A<i16>({-32768, 0, 32767}), A<i16>({-2}));
    add("a_uint16", A<u16>({0, 1, 65535}), A<u16>({7}));
    add("a_int32", A<i32>({std::numeric_limits<i32>::min(), 0, 2147483647}), A<i32>({9, 8}));
    add("a_uint32", A<u32>({0, 4294967295u}), A<u32>({1}));
    add("a_int64", A<i64>({std::numeric_limits<i64>::min(), -1, std::numeric_limits<i64>::max()}), A<i64>({0}));
    add("a_uint64", A<u64>({0, std::numeric_limits<u64>::max(), u64(1) << 63}), A<u64>({42}));
    add("a_cdouble", A<cdouble>({cdouble(1, 2), cdouble(-0.0, INF)}), A<cdouble>({cdouble(0, 0)}));
    add("a_csingle", A<csingle>({csingle(1, -2), csingle(0.5f, 0.25f)}), A<csingle>({csingle(0, 3)}));
    add("a_bool", A<bool>({true, false, false, true}), A<bool>({false}));
    add("a_fixed", A<double>({1.0, 2.0, 3.0}), A<double>({-1.0, -2.0, -3.0}));
    add("a_bounded", A<i16>({1, 2, 3, 4}), Value(NumericArray(DataTypes::int16_t)));
    add("a_empty", Value(NumericArray(DataTypes::uint8_t)), A<u8>({1, 2, 3}));

    add("m_double", MD<double>({2, 3}, {1, 2, 3, 4, 5, 6}), MD<double>({1, 1}, {9.5}));
    add("m_fixed", MD<i32>({2, 3}, {-1, 2, -3, 4, -5, 6}), MD<i32>({2, 3}, {0, 1, 2, 3, 4, 5}));
    std::vector<u8> r24(24);
    for (int i = 0; i < 24; ++i) r24[i] = static_cast<u8>(i);
    add("m_3d", MDv<u8>({2, 3, 4}, r24), MD<u8>({1, 2, 1}, {7, 8}));
    // Python `-3j` is complex(-0.0, -3.0)
    add("m_complex", MD<cdouble>({2, 2}, {cdouble(0, 1), cdouble(2, 0), cdouble(-0.0, -3), cdouble(4, 4)}),
        MD<cdouble>({1, 3}, {cdouble(0, 0), cdouble(1, 0), cdouble(2, 0)}));
    add("m_bool", MD<bool>({3, 2}, {true, false, true, true, false, false}), MD<bool>({1, 1}, {true}));

    add("s_inner", inner(1), inner(-2, std::string("\u00e9t\u00e9"), std::vector<double>{}));
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

    add("map_int",
        map_int({{std::numeric_limits<i32>::min(), S<double>(1.0)}, {-1, S<double>(-0.0)}, {0, S<double>(NaN)},
                 {2147483647, S<double>(F64_TINY)}}),
        map_int({}));
    add("map_str",
        map_str({{"", Str("empty key")}, {"key", Str("value")}, {"\u00fc\u00f1\u00ee \U0001F916", Str(UTF8_TEXT)}}),
        map_str({{"x", Str("")}}));
    add("map_struct", map_int({{1, inner(1)}, {-7, inner(-7)}}), map_int({{0, inner(0)}}));
    add("map_pod", map_str({{"first", test_pods(1, 1)}, {"second", test_pods(1, 2)}}), map_str({}));
    add("list_str", list({Str("a"), Str(""), Str(UTF8_TEXT)}), list({Str("only")}));
    add("list_struct", list({inner(1), inner(2), inner(3)}), list({}));
    add("list_arrays", list({A<double>({1.0}), Value(NumericArray(DataTypes::double_t)), A<double>({2.0, 3.0})}),
        list({A<double>({4.0})}));
    add("list_enum", list({color(red), color(green), color(blue), color(minus)}), list({color(green)}));
    add("list_na", list({vec3s(1, 1), vec3s(1, 2)}), list({vec3s(1, 8)}));
    add("map_null", Value(), map_int({{5, S<double>(5.5)}}));
    add("list_empty", list({}), list({Str("now"), Str("full")}));

    auto cat = varvalue_catalog();
    add("v_any", catalog_back(cat, "struct"), catalog_back(cat, "int32[*]"));
    std::vector<std::pair<std::string, Value>> all_kinds;
    for (const auto& [kind, v] : cat) all_kinds.push_back({kind, v.second});
    add("v_map", map_str(std::move(all_kinds)), map_str({}));
    add("v_list",
        list({catalog_back(cat, "string"), catalog_back(cat, "pod[]"), Value(), catalog_back(cat, "varvalue{int32}")}),
        list({}));
    add("v_null", Value(), catalog_back(cat, "string"));
    add("nolock_value", S<i32>(11), S<i32>(12));
    return P;
}

Value mix_result(double a, const std::string& b, Value c, Value d, Value e, Value f, Value g, const std::vector<std::int32_t>& h) {
    Value s = everything(0);
    auto* st = s.get_if<Structure>();
    st->set("f_double", S<double>(a));
    st->set("f_string", Str(b));
    st->set("f_inner", std::move(c));
    st->set("f_pod", std::move(d));
    st->set("f_vec", std::move(e));
    st->set("f_any", std::move(f));
    st->set("f_enum", std::move(g));
    std::vector<Value> strs;
    for (auto x : h) strs.push_back(Str(std::to_string(x)));
    st->set("f_strings", list(std::move(strs)));
    return s;
}

Value state_value(std::int32_t seq, const std::string& label) { return inner(seq, label, std::vector<double>{seq * 0.25}); }

// =====================================================================================================
// Comparison (as interop_values.deep_equal: exact bits; maps and struct fields by key)

std::string describe(const Value& v, int depth = 0);

std::string describe_numeric(const NumericArray& a) {
    std::ostringstream o;
    o << data_type_keyword(a.type()) << "[" << a.size() << "]{";
    dispatch_numeric(a.type(), [&](auto tag) {
        using T = typename decltype(tag)::type;
        auto view = a.view<T>();
        for (std::size_t i = 0; i < view.size() && i < 8; ++i) {
            if (i) o << ",";
            T x = view[i];
            if constexpr (std::is_same_v<T, bool>) o << (x ? "true" : "false");
            else if constexpr (detail::is_complex_v<T>) o << "(" << x.real() << "," << x.imag() << ")";
            else if constexpr (std::is_floating_point_v<T>) { char buf[40]; std::snprintf(buf, sizeof buf, "%.17g", double(x)); o << buf; }
            else if constexpr (sizeof(T) == 1) o << int(x);
            else o << x;
        }
        if (view.size() > 8) o << ",…";
    });
    o << "}";
    return o.str();
}

std::string describe(const Value& v, int depth) {
    if (depth > 2) return "…";
    switch (v.kind()) {
        case ValueKind::null: return "null";
        case ValueKind::numeric: return describe_numeric(*v.get_if<NumericArray>());
        case ValueKind::string: {
            auto s = *v.get_if<std::string>();
            if (s.size() > 40) s = s.substr(0, 40) + "…";
            return "\"" + s + "\"";
        }
        case ValueKind::multidim: {
            const auto& m = *v.get_if<MultiDimArray>();
            std::string d;
            for (auto x : m.dims) d += (d.empty() ? "" : ",") + std::to_string(x);
            return "md[" + d + "]" + describe_numeric(m.array);
        }
        case ValueKind::structure: {
            const auto& s = *v.get_if<Structure>();
            std::string out = s.type_name + "{";
            for (std::size_t i = 0; i < s.fields.size() && i < 6; ++i)
                out += (i ? ", " : "") + s.fields[i].name + "=" + describe(s.fields[i].value, depth + 1);
            return out + (s.fields.size() > 6 ? ", …}" : "}");
        }
        case ValueKind::pod: {
            const auto& p = *v.get_if<PodArray>();
            return "pod " + p.type_name + "[" + std::to_string(p.count) + "]" + (p.dims.empty() ? "" : " md");
        }
        case ValueKind::namedarray: {
            const auto& n = *v.get_if<NamedArray>();
            return "namedarray " + n.type_name + " " + describe_numeric(n.array) + (n.dims.empty() ? "" : " md");
        }
        case ValueKind::map_int32: return "{int32} of " + std::to_string(v.get_if<MapInt32>()->entries.size());
        case ValueKind::map_string: return "{string} of " + std::to_string(v.get_if<MapString>()->entries.size());
        case ValueKind::list: return "{list} of " + std::to_string(v.get_if<List>()->items.size());
        case ValueKind::enumeration: return "enum " + v.get_if<Enum>()->type_name + " " + std::to_string(v.get_if<Enum>()->value);
    }
    return "?";
}

std::optional<std::string> deep_equal(const Value& a, const Value& b, const std::string& path) {
    auto diff = [&](std::string what) -> std::optional<std::string> {
        return path + ": " + what + " (got " + describe(a) + ", want " + describe(b) + ")";
    };
    if (a.kind() != b.kind()) return diff(std::string(value_kind_name(a.kind())) + " is not " + std::string(value_kind_name(b.kind())));
    switch (a.kind()) {
        case ValueKind::null: return std::nullopt;
        case ValueKind::numeric:
            if (!(*a.get_if<NumericArray>() == *b.get_if<NumericArray>())) return diff("arrays differ");
            return std::nullopt;
        case ValueKind::string:
            if (*a.get_if<std::string>() != *b.get_if<std::string>()) return diff("strings differ");
            return std::nullopt;
        case ValueKind::multidim:
            if (!(*a.get_if<MultiDimArray>() == *b.get_if<MultiDimArray>())) return diff("multi-dim arrays differ");
            return std::nullopt;
        case ValueKind::structure: {
            const auto& x = *a.get_if<Structure>();
            const auto& y = *b.get_if<Structure>();
            if (x.type_name != y.type_name) return diff("struct type differs");
            if (x.fields.size() != y.fields.size()) return diff("field count differs");
            for (const auto& f : y.fields) {
                const Value* g = x.find(f.name);
                if (!g) return diff("missing field " + f.name);
                if (auto d = deep_equal(*g, f.value, path + "." + f.name)) return d;
            }
            return std::nullopt;
        }
        case ValueKind::pod: {
            const auto& x = *a.get_if<PodArray>();
            const auto& y = *b.get_if<PodArray>();
            if (x.type_name != y.type_name || x.count != y.count || x.dims != y.dims)
                return diff("pod type, count or dims differ");
            std::set<std::string> names(x.field_names.begin(), x.field_names.end());
            if (names != std::set<std::string>(y.field_names.begin(), y.field_names.end())) return diff("pod fields differ");
            for (std::size_t i = 0; i < y.count; ++i)
                for (const auto& n : y.field_names)
                    if (auto d = deep_equal(*x.field(i, n), *y.field(i, n), path + "[" + std::to_string(i) + "]." + n)) return d;
            return std::nullopt;
        }
        case ValueKind::namedarray:
            if (!(*a.get_if<NamedArray>() == *b.get_if<NamedArray>())) return diff("namedarrays differ");
            return std::nullopt;
        case ValueKind::map_int32: {
            const auto& x = *a.get_if<MapInt32>();
            const auto& y = *b.get_if<MapInt32>();
            if (x.entries.size() != y.entries.size()) return diff("map sizes differ");
            for (const auto& [k, v] : y.entries) {
                const Value* g = x.find(k);
                if (!g) return diff("missing key " + std::to_string(k));
                if (auto d = deep_equal(*g, v, path + "[" + std::to_string(k) + "]")) return d;
            }
            return std::nullopt;
        }
        case ValueKind::map_string: {
            const auto& x = *a.get_if<MapString>();
            const auto& y = *b.get_if<MapString>();
            if (x.entries.size() != y.entries.size()) return diff("map sizes differ");
            for (const auto& [k, v] : y.entries) {
                const Value* g = x.find(k);
                if (!g) return diff("missing key \"" + k + "\"");
                if (auto d = deep_equal(*g, v, path + "[\"" + k + "\"]")) return d;
            }
            return std::nullopt;
        }
        case ValueKind::list: {
            const auto& x = *a.get_if<List>();
            const auto& y = *b.get_if<List>();
            if (x.items.size() != y.items.size()) return diff("list lengths differ");
            for (std::size_t i = 0; i < x.items.size(); ++i)
                if (auto d = deep_equal(x.items[i], y.items[i], path + "[" + std::to_string(i) + "]")) return d;
            return std::nullopt;
        }
        case ValueKind::enumeration: {
            const auto& x = *a.get_if<Enum>();
            const auto& y = *b.get_if<Enum>();
            if (x.value != y.value || (!x.type_name.empty() && !y.type_name.empty() && x.type_name != y.type_name))
                return diff("enums differ");
            return std::nullopt;
        }
    }
    return diff("unknown kind");
}

// =====================================================================================================
// Checks

struct CheckFailed : std::runtime_error {
    using std::runtime_error::runtime_error;
};

std::string error_text(const RRError& e) { return e.name + ": " + e.message; }

void expect(bool cond, const std::string& what) {
    if (!cond) throw CheckFailed(what);
}

void expect_equal(const Value& got, const Value& want, const std::string& what) {
    if (auto d = deep_equal(got, want, what)) throw CheckFailed(*d);
}

template <class T>
T unwrap(Result<T> r, const std::string& what) {
    if (!r) throw CheckFailed(what + ": " + error_text(r.error()));
    if constexpr (!std::is_void_v<T>) return std::move(*r);
}

template <class T>
RRError expect_error(Result<T> r, MessageErrorType type, const std::string& what) {
    if (r) throw CheckFailed(what + ": expected " + std::string(error_name(type)) + ", nothing raised");
    if (r.error().type != type)
        throw CheckFailed(what + ": expected " + std::string(error_name(type)) + ", got " + error_text(r.error()));
    return r.error();
}

void wait_for(const std::function<bool()>& pred, std::chrono::milliseconds timeout, const std::string& what) {
    auto end = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < end) {
        if (pred()) return;
        std::this_thread::sleep_for(10ms);
    }
    throw CheckFailed("timed out after " + std::to_string(timeout.count()) + " ms waiting for " + what);
}

constexpr auto WAIT = 5000ms;

std::int32_t as_i32(const Value& v, const std::string& what) { return unwrap(v.as<std::int32_t>(), what); }

struct CheckResult {
    std::string section, name;
    bool ok;
    std::string error;
};

class Runner {
public:
    bool verbose = false;
    std::vector<CheckResult> results;
    std::string section;

    void check(const std::string& name, const std::function<void()>& fn) {
        if (verbose) std::cerr << "... " << section << "/" << name << std::endl;
        try {
            fn();
            results.push_back({section, name, true, {}});
        } catch (const std::exception& e) {
            std::cerr << "FAIL " << section << "/" << name << ": " << e.what() << std::endl;
            results.push_back({section, name, false, e.what()});
        }
    }
};

// =====================================================================================================
// experimental.interop_test (official_client.py, section by section)

class InteropRunner : public Runner {
public:
    explicit InteropRunner(ObjectProxy c) : c_(std::move(c)) {}

    static const std::vector<std::string>& sections() {
        static const std::vector<std::string> s = {"connection", "properties", "functions", "generators",
                                                   "events",     "objrefs",    "pipes",     "callbacks",
                                                   "wires",      "memories",   "session"};
        return s;
    }

    void run(const std::vector<std::string>& which) {
        for (const auto& s : which) {
            section = s;
            if (s == "connection") connection();
            else if (s == "properties") properties();
            else if (s == "functions") functions();
            else if (s == "generators") generators();
            else if (s == "events") events();
            else if (s == "objrefs") objrefs();
            else if (s == "pipes") pipes();
            else if (s == "callbacks") callbacks();
            else if (s == "wires") wires();
            else if (s == "memories") memories();
            else if (s == "session") session();
        }
    }

private:
    ObjectProxy c_;

    void connection() {
        check("service attributes", [&] {
            const auto& attrs = c_.client().info().attributes;
            auto v = unwrap(unpack_value_untyped(attrs), "attributes");
            const auto* m = v.get_if<MapString>();
            expect(m != nullptr, "attributes are not a {string} map: " + describe(v));
            const Value* purpose = m->find("purpose");
            expect(purpose != nullptr, "attribute purpose missing");
            expect_equal(*purpose, Str("interop test \u2713"), "attr purpose");
            const Value* version = m->find("version");
            expect(version != nullptr, "attribute version missing");
            expect_equal(*version, A<std::int32_t>({1, 0}), "attr version");
        });
        check("object type", [&] {
            expect(c_.type() == qn("Root"), "root type " + c_.type());
            // objectimplements travels as written in the definition ("Base"); the ObjectRef qualifies it
            const auto& raw = c_.client().info().object_implements;
            expect(raw == std::vector<std::string>{"Base"}, "objectimplements as received");
            expect(c_.ref().implements == std::vector<std::string>{qn("Base")}, "root implements " + qn("Base"));
        });
        check("reset", [&] { unwrap(c_.call("reset"), "reset"); });
    }

    void properties() {
        for (auto& [name, ab] : property_values()) {
            // (not a structured binding: clang 14 cannot capture one in a lambda)
            const auto& a = std::get<0>(ab);
            const auto& b = std::get<1>(ab);
            check(name + " get", [&, name = name] { expect_equal(unwrap(c_.get(name), name), a, name + " (A)"); });
            check(name + " set/get", [&, name = name] {
                unwrap(c_.set(name, b), "set " + name);
                expect_equal(unwrap(c_.get(name), name), b, name + " (B after set)");
            });
        }
        check("set rejected by service", [&] {
            expect_error(c_.set("p_int32", S<std::int32_t>(5)), MessageErrorType::InvalidArgument, "set p_int32 = 5");
        });
        check("set type mismatch rejected locally", [&] {
            expect_error(c_.set("p_int32", Str("five")), MessageErrorType::DataTypeMismatch, "set p_int32 = \"five\"");
        });
        check("base_name [readonly]", [&] { expect_equal(unwrap(c_.get("base_name"), "base_name"), Str(BASE_NAME), "base_name"); });
        check("ro_value [readonly] get", [&] { expect_equal(unwrap(c_.get("ro_value"), "ro_value"), S<std::int32_t>(RO_VALUE), "ro_value"); });
        check("ro_value [readonly] set fails", [&] {
            expect_error(c_.set("ro_value", S<std::int32_t>(1)), MessageErrorType::ReadOnlyMember, "set ro_value");
        });
        check("wo_value [writeonly] set", [&] {
            unwrap(c_.set("wo_value", S<std::int32_t>(1234)), "set wo_value");
            expect_equal(unwrap(c_.call("wo_value_last"), "wo_value_last"), S<std::int32_t>(1234), "wo_value_last");
        });
        check("wo_value [writeonly] get fails", [&] {
            expect_error(c_.get("wo_value"), MessageErrorType::WriteOnlyMember, "get wo_value");
        });
        check("unknown member", [&] { expect_error(c_.get("no_such_member"), MessageErrorType::MemberNotFound, "get no_such_member"); });
    }

    void functions() {
        check("add", [&] {
            expect_equal(unwrap(c_.call("add", {S<std::int32_t>(2), S<std::int32_t>(-5)}), "add"), S<std::int32_t>(-3), "add");
        });
        check("add overflow -> OutOfRange", [&] {
            expect_error(c_.call("add", {S<std::int32_t>(2147483647), S<std::int32_t>(1)}), MessageErrorType::OutOfRange, "add overflow");
        });
        check("void function", [&] { expect_equal(unwrap(c_.call("reset"), "reset"), Value(), "reset() return"); });
        check("make_inner", [&] {
            expect_equal(unwrap(c_.call("make_inner", {S<std::int32_t>(-4), Str(UTF8_TEXT), A<double>({1.0, -2.0})}), "make_inner"),
                         inner(-4, UTF8_TEXT, std::vector<double>{1.0, -2.0}), "make_inner");
        });
        check("wrong argument count", [&] {
            expect_error(c_.call("add", {S<std::int32_t>(2)}), MessageErrorType::InvalidArgument, "add(2)");
        });
        check("mix (8 parameters)", [&] {
            std::vector<Value> args = {S<double>(2.5), Str("mix \u00e9"), inner(8), test_pods(1, 6), vec3s(1, 2),
                                       A<std::uint16_t>({1, 2}), color(minus),
                                       list({S<std::int32_t>(3), S<std::int32_t>(-1), S<std::int32_t>(0)})};
            auto want = mix_result(2.5, "mix \u00e9", inner(8), test_pods(1, 6), vec3s(1, 2), A<std::uint16_t>({1, 2}),
                                   color(minus), {3, -1, 0});
            expect_equal(unwrap(c_.call("mix", args), "mix"), want, "mix");
        });
        check("user exception", [&] {
            auto e = expect_error(c_.call("throw_user", {Str("boom \u00fc")}), MessageErrorType::RemoteError, "throw_user");
            expect(e.name == qn("InteropError"), "errorname " + e.name);
            expect(e.message == "boom \u00fc", "error message " + e.message);
        });
        check("standard exception", [&] {
            auto e = expect_error(c_.call("throw_standard"), MessageErrorType::InvalidArgument, "throw_standard");
            expect(e.name == "RobotRaconteur.InvalidArgument", "errorname " + e.name);
            expect(e.message == "standard error from throw_standard", "error message " + e.message);
        });
        for (auto& [kind, sb] : varvalue_catalog()) {
            const auto& sent = std::get<0>(sb);
            const auto& back = std::get<1>(sb);
            check("echo varvalue " + kind, [&, kind = kind] { expect_equal(unwrap(c_.call("echo", {sent}), kind), back, kind); });
            check("catalog varvalue " + kind,
                  [&, kind = kind] { expect_equal(unwrap(c_.call("catalog", {Str(kind)}), kind), back, kind); });
        }
        check("catalog unknown -> InvalidArgument", [&] {
            expect_error(c_.call("catalog", {Str("no such kind")}), MessageErrorType::InvalidArgument, "catalog");
        });
    }

    void generators() {
        check("return generator to the end", [&] {
            auto g = unwrap(c_.generator("count_up", {S<std::int32_t>(5), S<std::int32_t>(3)}), "count_up");
            for (int want : {5, 6, 7}) expect_equal(unwrap(g.next(), "next"), S<std::int32_t>(want), "count_up value");
            expect_error(g.next(), MessageErrorType::StopIteration, "count_up end");
        });
        check("return generator NextAll", [&] {
            auto g = unwrap(c_.generator("count_up", {S<std::int32_t>(-2), S<std::int32_t>(4)}), "count_up");
            auto all = unwrap(g.next_all(), "next_all");
            expect(all.size() == 4, "NextAll gave " + std::to_string(all.size()) + " values");
            for (int i = 0; i < 4; ++i) expect_equal(all[i], S<std::int32_t>(-2 + i), "NextAll value");
        });
        check("return generator Close/Abort", [&] {
            auto g = unwrap(c_.generator("count_up", {S<std::int32_t>(0), S<std::int32_t>(10)}), "count_up");
            expect_equal(unwrap(g.next(), "next"), S<std::int32_t>(0), "first");
            unwrap(g.close(), "close");
            auto g2 = unwrap(c_.generator("count_up", {S<std::int32_t>(0), S<std::int32_t>(10)}), "count_up");
            expect_equal(unwrap(g2.next(), "next"), S<std::int32_t>(0), "first");
            unwrap(g2.abort(), "abort");
            expect_error(g2.next(), MessageErrorType::InvalidOperation, "next after abort");
        });
        check("parameter+return generator", [&] {
            auto g = unwrap(c_.generator("running_sum"), "running_sum");
            expect_equal(unwrap(g.next(S<double>(1.0)), "next"), S<double>(1.0), "sum 1");
            expect_equal(unwrap(g.next(S<double>(2.5)), "next"), S<double>(3.5), "sum 2");
            expect_equal(unwrap(g.next(S<double>(-0.5)), "next"), S<double>(3.0), "sum 3");
            expect_error(g.next(), MessageErrorType::InvalidArgument, "next without parameter");
            unwrap(g.close(), "close");
        });
        check("parameter generator (void return)", [&] {
            auto g = unwrap(c_.generator("collect"), "collect");
            expect_equal(unwrap(g.next(Str("a")), "next"), Value(), "void Next");
            unwrap(g.next(Str(UTF8_TEXT)), "next");
            unwrap(g.next(Str("")), "next");
            unwrap(g.close(), "close");
            expect_equal(unwrap(c_.get("collected"), "collected"), list({Str("a"), Str(UTF8_TEXT), Str("")}), "collected");
        });
        check("service saw close/abort", [&] {
            auto log = unwrap(c_.call("generator_log"), "generator_log");
            const auto* l = log.get_if<List>();
            expect(l != nullptr, "generator_log is not a list");
            for (std::string what : {"count_up:close", "count_up:abort", "running_sum:close", "collect:close"}) {
                bool found = std::any_of(l->items.begin(), l->items.end(), [&](const Value& v) {
                    auto* s = v.get_if<std::string>();
                    return s && *s == what;
                });
                expect(found, "generator_log lacks " + what);
            }
        });
        check("call on a generator function", [&] {
            expect_error(c_.call("count_up", {S<std::int32_t>(0), S<std::int32_t>(1)}), MessageErrorType::InvalidOperation,
                         "call count_up");
        });
    }

    void events() {
        std::mutex m;
        std::vector<std::vector<Value>> got;
        int empty = 0;
        auto s1 = unwrap(c_.subscribe("ev_values", [&](const std::string&, std::vector<Value>& args) {
            std::lock_guard lock(m);
            got.push_back(std::move(args));
        }), "subscribe ev_values");
        auto s2 = unwrap(c_.subscribe("ev_empty", [&](const std::string&, std::vector<Value>& args) {
            std::lock_guard lock(m);
            ++empty;
        }), "subscribe ev_empty");
        check("events fired on request", [&] {
            unwrap(c_.call("fire_events", {S<std::int32_t>(3)}), "fire_events");
            wait_for([&] {
                std::lock_guard lock(m);
                return got.size() >= 3 && empty >= 1;
            }, WAIT, "3 ev_values and 1 ev_empty");
            std::this_thread::sleep_for(50ms);
            std::lock_guard lock(m);
            expect(got.size() == 3, "ev_values count " + std::to_string(got.size()));
            // our client delivers in arrival order (one strand): seq 0, 1, 2
            for (std::size_t i = 0; i < got.size(); ++i) {
                expect(got[i].size() == 3, "ev_values has 3 arguments");
                expect_equal(got[i][0], S<std::int32_t>(std::int32_t(i)), "ev_values seq");
                expect_equal(got[i][1], Str("event " + std::to_string(i) + " \u2713"), "ev_values text");
                expect_equal(got[i][2], inner(std::int32_t(i), std::string("event"), std::vector<double>{i * 1.5}), "ev_values data");
            }
            expect(empty == 1, "ev_empty count " + std::to_string(empty));
        });
        c_.unsubscribe(s1);
        c_.unsubscribe(s2);
        // The handlers capture locals: make sure the strand is past any delivery before they go.
        (void)c_.client().query<int>([](ClientContext&, MonoTime) -> Result<int> { return 0; });
    }

    void objrefs() {
        check("objref plain + nested", [&] {
            auto ch = unwrap(c_.objref("child"), "child");
            expect(ch.type() == qn("Child"), "child type " + ch.type());
            expect(ch.path() == "interop.child", "child path " + ch.path());
            expect_equal(unwrap(ch.get("name"), "name"), Str("child[plain]"), "child name");
            expect_equal(unwrap(ch.get("value"), "value"), S<std::int32_t>(1), "child value");
            unwrap(ch.set("value", S<std::int32_t>(-9)), "set value");
            expect_equal(unwrap(ch.get("value"), "value"), S<std::int32_t>(-9), "child value after set");
            expect_equal(unwrap(ch.call("describe"), "describe"), Str("child[plain] value=-9"), "describe");
            auto leaf = unwrap(ch.objref("leaf"), "leaf");
            expect(leaf.path() == "interop.child.leaf", "leaf path " + leaf.path());
            expect_equal(unwrap(leaf.get("x"), "x"), S<double>(1.5), "leaf x");
            expect_equal(unwrap(leaf.call("scaled", {S<double>(2.0)}), "scaled"), S<double>(3.0), "leaf scaled");
        });
        check("objref indexed by int32", [&] {
            for (int k : {-1, 0, 7}) {
                auto ch = unwrap(c_.objref("child_by_int", k), "child_by_int");
                expect_equal(unwrap(ch.get("name"), "name"), Str("child[" + std::to_string(k) + "]"), "child_by_int name");
                expect_equal(unwrap(ch.get("value"), "value"), S<std::int32_t>(100 + k), "child_by_int value");
            }
            auto ch = unwrap(c_.objref("child_by_int", -1), "child_by_int[-1]");
            expect(ch.path() == "interop.child_by_int[%2d1]", "encoded int index " + ch.path());
        });
        check("objref indexed by string", [&] {
            int i = 0;
            for (std::string k : {"alpha", "with space_and-dash"}) {
                auto ch = unwrap(c_.objref("child_by_name", k), "child_by_name");
                expect_equal(unwrap(ch.get("name"), "name"), Str("child[" + k + "]"), "child_by_name name");
                expect_equal(unwrap(ch.get("value"), "value"), S<std::int32_t>(200 + i++), "child_by_name value");
            }
            auto ch = unwrap(c_.objref("child_by_name", std::string("with space_and-dash")), "child_by_name");
            expect(ch.path() == "interop.child_by_name[with%20space%5fand%2ddash]", "encoded string index " + ch.path());
            auto leaf = unwrap(ch.objref("leaf"), "leaf");
            expect_equal(unwrap(leaf.get("x"), "x"), S<double>(201.5), "leaf below an indexed objref");
        });
        check("objref unknown index -> ObjectNotFound", [&] {
            expect_error(c_.objref("child_by_int", 12345), MessageErrorType::ObjectNotFound, "child_by_int[12345]");
        });
        check("objref wrong index kind", [&] {
            expect_error(c_.objref("child_by_int", std::string("x")), MessageErrorType::InvalidArgument, "child_by_int[\"x\"]");
        });
        check("objref varobject", [&] {
            auto o = unwrap(c_.objref("any_obj"), "any_obj");
            expect(o.type() == qn("Leaf"), "varobject type " + o.type());
            expect_equal(unwrap(o.get("x"), "x"), S<double>(-3.5), "varobject x");
        });
        check("service path released", [&] {
            auto ch = unwrap(c_.objref("child_by_int", 0), "child_by_int[0]");
            expect_equal(unwrap(ch.get("value"), "value"), S<std::int32_t>(100), "before release");
            unwrap(c_.call("release_child", {S<std::int32_t>(0)}), "release_child");
            // The ServicePathReleasedReq arrives after the call's answer: wait until the path is forgotten.
            wait_for([&] {
                return !c_.client().query<bool>([p = ch.path()](ClientContext& ctx, MonoTime) -> Result<bool> {
                    return ctx.object(p).has_value();
                }).value();
            }, WAIT, "the released path to be dropped");
            expect_error(ch.get("value"), MessageErrorType::ObjectNotFound, "released object");
            auto ch2 = unwrap(c_.objref("child_by_int", 0), "child_by_int[0] again");
            expect_equal(unwrap(ch2.get("value"), "value"), S<std::int32_t>(100), "after release, requested again");
        });
    }

    void pipes() {
        check("pipe echo with acks", [&] {
            auto ep = unwrap(c_.pipe_connect("p_echo", -1), "connect p_echo");
            unwrap(ep.set_request_ack(true), "request acks");
            std::vector<Value> sent;
            for (int i = 0; i < 3; ++i) sent.push_back(inner(i, "pipe " + std::to_string(i)));
            std::vector<std::uint32_t> numbers;
            for (auto& p : sent) numbers.push_back(unwrap(ep.send(p), "send"));
            expect(numbers == std::vector<std::uint32_t>{1, 2, 3}, "packet numbers 1, 2, 3");
            for (std::size_t i = 0; i < sent.size(); ++i)
                expect_equal(unwrap(ep.receive(WAIT), "receive"), sent[i], "echoed packet " + std::to_string(i));
            unwrap(ep.wait_acks(3, WAIT), "3 packet acks");
            auto acks = ep.acks();
            std::sort(acks.begin(), acks.end());
            expect(acks == numbers, "acks for packets 1, 2, 3");
            unwrap(ep.close(), "close");
        });
        check("pipe connect with fixed index", [&] {
            auto ep = unwrap(c_.pipe_connect("p_echo", 3), "connect p_echo[3]");
            expect(ep.index() == 3, "pipe index " + std::to_string(ep.index()));
            unwrap(ep.send(inner(3)), "send");
            expect_equal(unwrap(ep.receive(WAIT), "receive"), inner(3), "echo on index 3");
            unwrap(ep.close(), "close");
        });
        check("pipe send type mismatch", [&] {
            auto ep = unwrap(c_.pipe_connect("p_echo", -1), "connect p_echo");
            expect_error(ep.send(S<double>(1.0)), MessageErrorType::DataTypeMismatch, "send double on an Inner pipe");
            unwrap(ep.close(), "close");
        });
        check("unreliable pipe echo", [&] {
            auto ep = unwrap(c_.pipe_connect("p_unreliable", -1), "connect p_unreliable");
            expect(ep.info().unreliable, "endpoint is unreliable");
            for (const std::string& s : {std::string("u1"), UTF8_TEXT}) {
                unwrap(ep.send(Str(s)), "send");
                expect_equal(unwrap(ep.receive(WAIT), "receive"), Str(s), "unreliable echo");
            }
            unwrap(ep.close(), "close");
        });
        check("readonly pipe stream + closed by service", [&] {
            auto ep = unwrap(c_.pipe_connect("p_stream", -1), "connect p_stream");
            expect_error(ep.send(A<double>({1.0})), MessageErrorType::ReadOnlyMember, "send on a readonly pipe");
            std::atomic<bool> closed_cb{false};
            ep.set_closed_handler([&](const RRError&) { closed_cb = true; });
            unwrap(c_.call("send_stream", {S<std::int32_t>(4)}), "send_stream");
            for (int i = 0; i < 4; ++i)
                expect_equal(unwrap(ep.receive(WAIT), "receive"), A<double>({double(i), i * 0.5}), "stream packet " + std::to_string(i));
            unwrap(c_.call("close_stream"), "close_stream");
            unwrap(ep.wait_closed(WAIT), "service closed the pipe endpoint");
            wait_for([&] { return closed_cb.load(); }, WAIT, "closed handler");
            expect_error(ep.receive(100ms), MessageErrorType::ConnectionError, "receive after close");
            unwrap(ep.close(), "release");
        });
    }

    void callbacks() {
        std::mutex m;
        std::vector<std::string> labels;
        std::vector<Value> infos;
        unwrap(c_.set_callback("cb_compute", [&](std::vector<Value>& args) -> Result<Value> {
            auto x = args[0].as<double>();
            if (!x) return x.take_error();
            std::lock_guard lock(m);
            labels.push_back(args[1].as<std::string>().value());
            return S<double>(*x * 2.0);
        }), "set cb_compute");
        unwrap(c_.set_callback("cb_notify", [&](std::vector<Value>& args) -> Result<Value> {
            std::lock_guard lock(m);
            infos.push_back(std::move(args[0]));
            return Value();
        }), "set cb_notify");
        check("callbacks invoked by the service", [&] {
            expect_equal(unwrap(c_.call("call_callbacks", {S<double>(3.0)}), "call_callbacks"), S<double>(7.0), "call_callbacks result");
            std::lock_guard lock(m);
            expect(labels == std::vector<std::string>{CALLBACK_LABEL}, "callback label");
            expect(infos.size() == 1, "one cb_notify");
            expect_equal(infos[0], inner(77, std::string("notify")), "callback struct");
        });
        check("callback error reaches the service", [&] {
            unwrap(c_.set_callback("cb_compute", [](std::vector<Value>&) -> Result<Value> {
                return fail(MessageErrorType::InvalidOperation, "refused by the client");
            }), "set cb_compute");
            auto e = expect_error(c_.call("call_callbacks", {S<double>(1.0)}), MessageErrorType::InvalidOperation, "call_callbacks");
            expect(e.message.find("refused by the client") != std::string::npos, "error text " + e.message);
        });
        unwrap(c_.set_callback("cb_compute", nullptr), "clear cb_compute");
        unwrap(c_.set_callback("cb_notify", nullptr), "clear cb_notify");
    }

    void wires() {
        check("readonly wire periodic + on demand + peek", [&] {
            auto conn = unwrap(c_.wire_connect("w_state"), "connect w_state");
            expect_error(conn.set_out_value(inner(0)), MessageErrorType::ReadOnlyMember, "set OutValue of a readonly wire");
            std::set<std::int32_t> ticks;
            unwrap(conn.wait_value([&](const WireValue& v) {
                if (*v.value.field("label")->get_if<std::string>() == "tick") ticks.insert(v.value.field("id")->as<std::int32_t>().value());
                return ticks.size() >= 2;
            }, 4000ms, 0), "two periodic w_state updates");
            unwrap(c_.call("update_state", {S<std::int32_t>(1234)}), "update_state");
            auto demand = unwrap(conn.wait_value([](const WireValue& v) {
                return *v.value.field("label")->get_if<std::string>() == "demand" && v.value.field("id")->as<std::int32_t>().value() == 1234;
            }, WAIT, 0), "w_state on demand");
            expect_equal(demand.value, state_value(1234, "demand"), "w_state");
            auto in = unwrap(conn.in_value(), "InValue valid");
            auto label = *in.value.field("label")->get_if<std::string>();
            expect(label == "tick" || label == "demand", "InValue label " + label);
            auto peek = unwrap(c_.peek_in_value("w_state"), "PeekInValue");
            auto plabel = *peek.value.field("label")->get_if<std::string>();
            expect(plabel == "tick" || plabel == "demand", "peeked w_state label " + plabel);
            expect(peek.timestamp.seconds > 1500000000, "packet time stamp is recent: " + std::to_string(peek.timestamp.seconds));
            expect(in.timestamp.seconds > 1500000000, "InValue time stamp is recent");
            unwrap(conn.close(), "close");
        });
        check("two-way wire + peek/poke", [&] {
            auto conn = unwrap(c_.wire_connect("w_both"), "connect w_both");
            unwrap(conn.set_out_value(A<double>({1.0, 2.0, 3.0})), "set OutValue");
            unwrap(conn.wait_value([](const WireValue& v) { return !deep_equal(v.value, A<double>({3.0, 2.0, 1.0}), ""); }, WAIT, 0),
                   "reversed echo");
            expect_equal(unwrap(conn.in_value(), "InValue").value, A<double>({3.0, 2.0, 1.0}), "InValue");
            expect_equal(unwrap(conn.out_value(), "OutValue").value, A<double>({1.0, 2.0, 3.0}), "OutValue");
            expect_equal(unwrap(c_.peek_in_value("w_both"), "PeekInValue").value, A<double>({3.0, 2.0, 1.0}), "PeekInValue");
            expect_equal(unwrap(c_.peek_out_value("w_both"), "PeekOutValue").value, A<double>({1.0, 2.0, 3.0}), "PeekOutValue");
            unwrap(c_.poke_out_value("w_both", A<double>({9.0, -0.0})), "PokeOutValue");
            expect_equal(unwrap(c_.peek_out_value("w_both"), "PeekOutValue").value, A<double>({9.0, -0.0}), "PeekOutValue after poke");
            unwrap(conn.close(), "close");
        });
        check("in value lifespan", [&] {
            auto conn = unwrap(c_.wire_connect("w_state"), "connect w_state");
            unwrap(conn.wait_value([](const WireValue&) { return true; }, WAIT, 0), "a w_state value");
            unwrap(conn.in_value(), "InValue with the default lifespan (forever)");
            unwrap(conn.set_lifespans(1, -1), "lifespan 1 ms");
            // values come every 200 ms: most of the time the newest one is older than 1 ms
            std::optional<RRError> expired;
            wait_for([&] {
                auto v = conn.in_value();
                if (!v) expired = v.error();
                return !v;
            }, WAIT, "the InValue to expire");
            expect(expired->type == MessageErrorType::ValueNotSet, "expired InValue: " + error_text(*expired));
            unwrap(conn.set_lifespans(-1, -1), "lifespan forever");
            unwrap(conn.in_value(), "InValue valid again");
            unwrap(conn.close(), "close");
        });
        check("writeonly wire + poke", [&] {
            auto conn = unwrap(c_.wire_connect("w_sink"), "connect w_sink");
            expect_error(conn.in_value(), MessageErrorType::WriteOnlyMember, "InValue of a writeonly wire");
            unwrap(conn.set_out_value(S<std::int32_t>(42)), "set OutValue");
            wait_for([&] { return as_i32(unwrap(c_.call("w_sink_value"), "w_sink_value"), "w_sink_value") == 42; }, WAIT, "w_sink value 42");
            unwrap(conn.close(), "close");
            unwrap(c_.poke_out_value("w_sink", S<std::int32_t>(-43)), "PokeOutValue");
            expect_equal(unwrap(c_.call("w_sink_value"), "w_sink_value"), S<std::int32_t>(-43), "w_sink after poke");
            expect_equal(unwrap(c_.peek_out_value("w_sink"), "PeekOutValue").value, S<std::int32_t>(-43), "w_sink PeekOutValue");
        });
    }

    void memories() {
        check("memory double[]", [&] {
            expect(unwrap(c_.memory_length("mem_double"), "Length") == 100, "Length");
            std::vector<double> want;
            for (int i = 10; i < 20; ++i) want.push_back(i * 0.5);
            expect_equal(unwrap(c_.memory_read("mem_double", 10, 10), "read"), Av<double>(want), "read");
            unwrap(c_.memory_write("mem_double", 5, A<double>({-1.0, -2.0, -3.0})), "write");
            expect_equal(unwrap(c_.memory_read("mem_double", 4, 5), "read"), A<double>({2.0, -1.0, -2.0, -3.0, 4.0}), "read after write");
        });
        check("memory int32[*]", [&] {
            auto dims = unwrap(c_.memory_dimensions("mem_md"), "Dimensions");
            expect(dims == std::vector<std::uint64_t>{4, 5}, "Dimensions");
            expect(unwrap(c_.memory_dim_count("mem_md"), "DimCount") == 2, "DimCount");
            std::vector<std::int32_t> block;
            for (int j = 1; j < 4; ++j)
                for (int i = 1; i < 3; ++i) block.push_back(-10 + i + 4 * j);
            expect_equal(unwrap(c_.memory_read("mem_md", {1, 1}, {2, 3}), "read block"), MDv<std::int32_t>({2, 3}, block), "read block");
            // numpy [[7, 8], [9, 10]] in column-major order
            unwrap(c_.memory_write("mem_md", {0, 0}, MD<std::int32_t>({2, 2}, {7, 9, 8, 10})), "write");
            std::vector<std::int32_t> all;
            for (int k = 0; k < 20; ++k) all.push_back(-10 + k);
            all[0] = 7, all[1] = 9, all[4] = 8, all[5] = 10;
            expect_equal(unwrap(c_.memory_read("mem_md", {0, 0}, {4, 5}), "read"), MDv<std::int32_t>({4, 5}, all), "read after write");
        });
        check("memory pod[]", [&] {
            expect(unwrap(c_.memory_length("mem_pod"), "Length") == 4, "Length");
            expect_equal(unwrap(c_.memory_read("mem_pod", 1, 2), "read"), test_pods(2, 31), "read");
            unwrap(c_.memory_write("mem_pod", 0, test_pods(1, 99)), "write");
            expect_equal(unwrap(c_.memory_read("mem_pod", 0, 4), "read"), pods_of_seeds({99, 31, 32, 33}), "read after write");
        });
        check("memory pod[*]", [&] {
            expect(unwrap(c_.memory_dimensions("mem_pod_md"), "Dimensions") == std::vector<std::uint64_t>{2, 3}, "Dimensions");
            expect_equal(unwrap(c_.memory_read("mem_pod_md", {0, 0}, {2, 3}), "read"), test_pods(6, 40, {2, 3}), "read");
            unwrap(c_.memory_write("mem_pod_md", {1, 1}, test_pods(2, 7, {1, 2})), "write");
            expect_equal(unwrap(c_.memory_read("mem_pod_md", {0, 0}, {2, 3}), "read"), pods_of_seeds({40, 41, 42, 7, 44, 8}, {2, 3}),
                         "read after write");
        });
        check("memory namedarray[]", [&] {
            expect(unwrap(c_.memory_length("mem_na"), "Length") == 5, "Length");
            expect_equal(unwrap(c_.memory_read("mem_na", 2, 3), "read"), vec3s(3, 52), "read");
            unwrap(c_.memory_write("mem_na", 4, vec3s(1, 70)), "write");
            expect_equal(unwrap(c_.memory_read("mem_na", 2, 3), "read"), vec3s_of_seeds({52, 53, 70}), "read after write");
        });
        check("memory namedarray[*]", [&] {
            expect(unwrap(c_.memory_dimensions("mem_na_md"), "Dimensions") == std::vector<std::uint64_t>{3, 2}, "Dimensions");
            expect_equal(unwrap(c_.memory_read("mem_na_md", {0, 0}, {3, 2}), "read"), vec3s(6, 60, {3, 2}), "read");
        });
        check("memory [readonly]", [&] {
            std::vector<std::uint8_t> want;
            for (int i = 0; i < 16; ++i) want.push_back(std::uint8_t(i * 3));
            expect_equal(unwrap(c_.memory_read("mem_ro", 0, 16), "read"), Av<std::uint8_t>(want), "read");
            expect_error(c_.memory_write("mem_ro", 0, A<std::uint8_t>({1})), MessageErrorType::ReadOnlyMember, "write to readonly memory");
        });
    }

    void session() {
        check("monitor lock", [&] {
            unwrap(c_.monitor_enter(5), "MonitorEnter");
            auto v = c_.get("ro_value");
            unwrap(c_.monitor_exit(), "MonitorExit");
            expect_equal(unwrap(std::move(v), "ro_value"), S<std::int32_t>(RO_VALUE), "read under monitor lock");
        });
        check("final reset", [&] { unwrap(c_.call("reset"), "reset"); });
    }
};

// =====================================================================================================
// Reynard the Robot (reynard_official_client.py)

const std::string REYNARD_ROOT = "experimental.reynard_the_robot.Reynard";

std::vector<double> doubles(const Value& v, const std::string& what) {
    const auto* a = v.get_if<NumericArray>();
    if (!a || a->type() != DataTypes::double_t) throw CheckFailed(what + " is not a double array: " + describe(v));
    std::vector<double> out;
    for (double d : a->view<double>()) out.push_back(d);
    return out;
}

void expect_close(const std::vector<double>& got, const std::vector<double>& want, double tol, const std::string& what) {
    bool ok = got.size() == want.size();
    for (std::size_t i = 0; ok && i < got.size(); ++i) ok = std::fabs(got[i] - want[i]) <= tol;
    if (!ok) {
        std::ostringstream o;
        o << what << ": got [";
        for (auto d : got) o << d << " ";
        o << "], want [";
        for (auto d : want) o << d << " ";
        o << "] (tolerance " << tol << ")";
        throw CheckFailed(o.str());
    }
}

class ReynardRunner : public Runner {
public:
    ReynardRunner(ObjectProxy c, bool chat) : c_(std::move(c)), chat_(chat) {}

    void run() {
        section = "reynard";
        check("definition", [&] {
            expect(c_.type() == REYNARD_ROOT, "root object type " + c_.type());
            auto m = c_.client().query<std::string>([](ClientContext& ctx, MonoTime) -> Result<std::string> {
                auto d = ctx.member_definition(ctx.root().path, "state");
                if (!d) return d.take_error();
                return (*d)->type.to_string();
            });
            expect(unwrap(std::move(m), "state member") == "ReynardState", "state wire type");
        });
        check("reset", [&] {
            unwrap(c_.call("drive_robot", {S(0.0), S(0.0), S(-1.0), S(false)}), "drive_robot");
            unwrap(c_.call("drive_arm", {S(0.0), S(0.0), S(0.0), S(-1.0), S(false)}), "drive_arm");
            unwrap(c_.call("teleport", {S(0.0), S(0.0)}), "teleport");
            unwrap(c_.call("setf_arm_position", {S(0.0), S(0.0), S(0.0)}), "setf_arm_position");
        });
        check("position", [&] {
            auto p = doubles(unwrap(c_.get("robot_position"), "robot_position"), "robot_position");
            expect(p.size() == 2, "robot_position has 2 items");
            expect(p[0] >= -1 && p[0] <= 1 && p[1] >= -0.5 && p[1] <= 0.5, "robot_position out of bounds");
            expect_close(p, {0.0, 0.0}, 1e-12, "robot_position after reset");
        });
        check("color", [&] {
            auto orig = unwrap(c_.get("color"), "color");
            expect(doubles(orig, "color").size() == 3, "color has 3 items");
            unwrap(c_.set("color", A<double>({0.2, 0.4, 0.6})), "set color");
            expect_close(doubles(unwrap(c_.get("color"), "color"), "color"), {0.2, 0.4, 0.6}, 0.0, "color read back");
            for (auto bad : {A<double>({2.0, 0.0, 0.0}), A<double>({-0.1, 0.0, 0.0}), A<double>({0.5, 0.5}),
                             A<double>({0.1, 0.2, 0.3, 0.4})})
                expect_error(c_.set("color", bad), MessageErrorType::InvalidArgument, "color = " + describe(bad));
            expect_close(doubles(unwrap(c_.get("color"), "color"), "color"), {0.2, 0.4, 0.6}, 0.0, "color after rejected sets");
            unwrap(c_.set("color", orig), "restore color");
            expect_equal(unwrap(c_.get("color"), "color"), orig, "color restored");
        });
        check("state", [&] {
            state_ = unwrap(c_.wire_connect("state"), "connect state");
            auto t0 = std::chrono::steady_clock::now();
            unwrap(state_.wait_value([](const WireValue&) { return true; }, 3000ms, 0), "first state value");
            auto n0 = state_.values_received();
            std::this_thread::sleep_for(1500ms);
            auto n = state_.values_received() - n0;
            expect(n >= 3, "only " + std::to_string(n) + " state values in 1.5 s");  // ~30 unloaded; liveness only
            auto v = unwrap(state_.in_value(), "InValue").value;
            expect(v.field("time") && v.field("time")->as<double>(), "state.time is a double");
            for (auto [name, size] : {std::pair<const char*, std::size_t>{"robot_position", 2}, {"arm_position", 3},
                                      {"robot_velocity", 2}, {"arm_velocity", 3}}) {
                expect(v.field(name) != nullptr, std::string("state.") + name + " missing");
                expect(doubles(*v.field(name), name).size() == size, std::string("state.") + name + " shape");
            }
            auto pos = doubles(unwrap(c_.get("robot_position"), "robot_position"), "robot_position");
            expect_close(doubles(*v.field("robot_position"), "wire robot_position"), {pos[0] * 1000.0, pos[1] * 1000.0}, 1e-6,
                         "state.robot_position (mm) vs robot_position (m)");
            expect_close(doubles(*v.field("robot_velocity"), "robot_velocity"), {0.0, 0.0}, 0.0, "state.robot_velocity at rest");
            auto peek = unwrap(c_.peek_in_value("state"), "PeekInValue");
            expect(doubles(*peek.value.field("robot_position"), "peek robot_position").size() == 2, "PeekInValue robot_position");
            (void)t0;
        });
        check("teleport", [&] {
            expect(bool(state_), "state wire connected");
            std::uint64_t before = state_.values_received();
            unwrap(c_.call("teleport", {S(0.3), S(-0.2)}), "teleport");
            expect_close(doubles(unwrap(c_.get("robot_position"), "robot_position"), "p"), {0.3, -0.2}, 1e-9, "robot_position right after teleport");
            for (auto bad : {std::pair{1.5, 0.0}, std::pair{0.0, 0.6}, std::pair{-1.01, 0.0}})
                expect_error(c_.call("teleport", {S(bad.first), S(bad.second)}), MessageErrorType::InvalidArgument, "teleport out of range");
            expect_close(doubles(unwrap(c_.get("robot_position"), "robot_position"), "p"), {0.3, -0.2}, 1e-9, "after rejected teleports");
            unwrap(state_.wait_value([](const WireValue& v) {
                auto p = v.value.field("robot_position");
                const auto* a = p ? p->get_if<NumericArray>() : nullptr;
                return a && a->size() == 2 && std::fabs(a->at<double>(0) - 300.0) < 1e-6 && std::fabs(a->at<double>(1) + 200.0) < 1e-6;
            }, 3000ms, before), "teleport on the state wire (mm)");
            unwrap(c_.call("teleport", {S(0.0), S(0.0)}), "teleport back");
            expect_close(doubles(unwrap(c_.get("robot_position"), "robot_position"), "p"), {0.0, 0.0}, 1e-12, "teleport back to 0");
        });
        check("drive", [&] {
            expect(bool(state_), "state wire connected");
            unwrap(c_.call("teleport", {S(0.0), S(0.0)}), "teleport");
            unwrap(state_.wait_value([](const WireValue& v) {
                return v.value.field("robot_position")->get_if<NumericArray>()->at<double>(0) == 0.0;
            }, 3000ms, state_.values_received() - 1), "the robot at x = 0 on the state wire");
            const std::uint64_t before = state_.values_received();
            auto t0 = std::chrono::steady_clock::now();
            unwrap(c_.call("drive_robot", {S(0.1), S(0.05), S(1.0), S(false)}), "drive_robot");
            auto call_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            expect(call_s < 0.5, "drive_robot(wait=false) took " + std::to_string(call_s) + " s");
            auto moving = unwrap(state_.wait_value([](const WireValue& v) {
                return v.value.field("robot_position")->get_if<NumericArray>()->at<double>(0) > 0.0;
            }, 2000ms, before), "motion on the state wire");
            (void)moving;
            // The wire reads position and velocity one after the other (no lock in Reynard), and under load
            // the simulation may step late: look for the velocity among the values since the call.
            auto driving = unwrap(state_.wait_value([](const WireValue& v) {
                auto a = v.value.field("robot_velocity")->get_if<NumericArray>();
                return a->at<double>(0) != 0.0 || a->at<double>(1) != 0.0;
            }, 2000ms, before), "a velocity on the state wire");
            expect_close(doubles(*driving.value.field("robot_velocity"), "v"), {100.0, 50.0}, 1e-9, "state.robot_velocity while driving (mm/s)");
            const std::uint64_t moved = state_.values_received();
            unwrap(state_.wait_value([](const WireValue& v) {
                auto a = v.value.field("robot_velocity")->get_if<NumericArray>();
                return a->at<double>(0) == 0.0 && a->at<double>(1) == 0.0;
            }, 4000ms, moved), "robot_velocity back to 0 after the 1 s timeout");
            auto stop_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            expect(stop_s >= 0.9, "stopped after " + std::to_string(stop_s) + " s, before its 1 s timeout");
            std::this_thread::sleep_for(150ms);
            auto p = doubles(unwrap(c_.get("robot_position"), "robot_position"), "p");
            // ~0.1 m after 1 s; the simulation steps by sleeping, so under load it covers less
            expect(p[0] > 0.0 && p[0] <= 0.13, "after 1 s at 0.1 m/s x = " + std::to_string(p[0]));
            expect_close({p[1]}, {p[0] / 2.0}, 1e-9, "y/x ratio 1/2");
            std::this_thread::sleep_for(300ms);
            expect_close(doubles(unwrap(c_.get("robot_position"), "robot_position"), "p"), p, 0.0, "robot stays put after its timeout");
            unwrap(c_.call("drive_robot", {S(0.0), S(0.0), S(-1.0), S(false)}), "stop");
            unwrap(c_.call("teleport", {S(0.0), S(0.0)}), "teleport back");
        });
        check("message", [&] {
            std::mutex m;
            std::vector<std::string> got;
            auto sub = unwrap(c_.subscribe("new_message", [&](const std::string&, std::vector<Value>& args) {
                std::lock_guard lock(m);
                got.push_back(args.at(0).as<std::string>().value());
            }), "subscribe new_message");
            unwrap(c_.call("say", {Str("Hello from our C++ client: h\u00e9llo \u2713 \U0001F98A")}), "say");
            std::this_thread::sleep_for(1000ms);
            {
                std::lock_guard lock(m);
                expect(got.empty(), "say() fired new_message");
            }
            if (chat_) {
                const std::string chat = "chat for our client: \u00fcn\u00efcode \u2713 \U0001F98A";
                std::cout << "CHAT " << nlohmann::json(chat).dump() << std::endl;
                wait_for([&] {
                    std::lock_guard lock(m);
                    return !got.empty();
                }, 10000ms, "new_message event after a web UI chat message");
                std::this_thread::sleep_for(300ms);
                std::lock_guard lock(m);
                expect(got.size() == 1, "new_message fired " + std::to_string(got.size()) + " times");
                expect(got[0] == chat, "new_message carried \"" + got[0] + "\"");
            }
            c_.unsubscribe(sub);
            (void)c_.client().query<int>([](ClientContext&, MonoTime) -> Result<int> { return 0; });
        });
        if (state_) {
            auto r = state_.close();
            if (!r) results.push_back({section, "state_close", false, error_text(r.error())});
            state_ = {};
        }
    }

private:
    ObjectProxy c_;
    bool chat_;
    rr::client::WireConnection state_;
};

// =====================================================================================================

std::vector<std::string> split(const std::string& s, char sep) {
    std::vector<std::string> out;
    std::string cur;
    for (char ch : s) {
        if (ch == sep) {
            if (!cur.empty()) out.push_back(cur);
            cur.clear();
        } else {
            cur += ch;
        }
    }
    if (!cur.empty()) out.push_back(cur);
    return out;
}

int usage() {
    std::cerr << "usage: rr_interop_client URL [--disable-message4] [--timeout S] [--idle S] [--verbose] [--only SECTION,...]\n"
                 "       rr_interop_client --reynard URL [--timeout S] [--verbose] [--chat]\n";
    return 2;
}

}  // namespace

int main(int argc, char** argv) {
    std::string url;
    bool reynard = false, chat = false, verbose = false, disable_message4 = false;
    double timeout_s = 120, idle_s = 0;
    std::vector<std::string> only;
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        if (a == "--reynard") reynard = true;
        else if (a == "--chat") chat = true;
        else if (a == "--verbose") verbose = true;
        else if (a == "--disable-message4") disable_message4 = true;
        else if (a == "--timeout" && i + 1 < argc) timeout_s = std::stod(argv[++i]);
        else if (a == "--idle" && i + 1 < argc) idle_s = std::stod(argv[++i]);
        else if (a == "--only" && i + 1 < argc) only = split(argv[++i], ',');
        else if (!a.empty() && a[0] != '-' && url.empty()) url = a;
        else return usage();
    }
    if (url.empty()) return usage();
    if (only.empty()) only = InteropRunner::sections();
    for (const auto& s : only)
        if (std::find(InteropRunner::sections().begin(), InteropRunner::sections().end(), s) == InteropRunner::sections().end())
            return usage();

    nlohmann::json summary = {{"ok", false}, {"url", url}, {"client", "rr_interop_client"}};
    std::thread([timeout_s, url] {
        std::this_thread::sleep_for(std::chrono::duration<double>(timeout_s));
        std::cout << nlohmann::json({{"ok", false}, {"url", url}, {"error", "overall timeout"}}).dump() << std::endl;
        std::_Exit(3);
    }).detach();

    int rc = 2;
    {
        rr::client::IoThreads io(2);
        rr::client::ClientOptions options;
        options.enable_message4 = !disable_message4;
        auto client = Client::connect(io.executor(), url, options);
        if (!client) {
            summary["error"] = "connect failed: " + error_text(client.error());
            std::cout << summary.dump() << std::endl;
            return 2;
        }
        std::vector<CheckResult> results;
        if (reynard) {
            ReynardRunner r((*client)->root(), chat);
            r.verbose = verbose;
            r.run();
            results = std::move(r.results);
            summary["sections"] = {"reynard"};
        } else {
            InteropRunner r((*client)->root());
            r.verbose = verbose;
            r.run(only);
            results = std::move(r.results);
            summary["sections"] = only;
        }
        if (idle_s > 0) {
            // Stay connected and idle: heartbeats (and keep-alives) must keep the session up.
            std::this_thread::sleep_for(std::chrono::duration<double>(idle_s));
            bool open = (*client)->is_open();
            results.push_back({"session", "still connected after idle", open, open ? "" : "connection dropped while idle"});
            if (open && !reynard) {
                auto v = (*client)->root().get("ro_value");
                results.push_back({"session", "request after idle", bool(v), v ? "" : error_text(v.error())});
            }
        }
        if (auto closed = (*client)->close_wait(); !closed) results.push_back({"session", "disconnect", false, error_text(closed.error())});
        client = fail(MessageErrorType::ConnectionError, "released");

        nlohmann::json failures = nlohmann::json::array();
        nlohmann::json per_section = nlohmann::json::object();
        int passed = 0;
        for (const auto& r : results) {
            auto& ps = per_section[r.section];
            if (ps.is_null()) ps = {0, 0};
            ps[1] = ps[1].get<int>() + 1;
            if (r.ok) {
                ++passed;
                ps[0] = ps[0].get<int>() + 1;
            } else {
                failures.push_back({{"check", r.section + "/" + r.name}, {"error", r.error}});
            }
        }
        summary["ok"] = failures.empty();
        summary["passed"] = passed;
        summary["failed"] = failures.size();
        summary["failures"] = failures;
        summary["per_section"] = per_section;
        rc = failures.empty() ? 0 : 1;
    }
    std::cout << summary.dump() << std::endl;
    return rc;
}
