// Test-only: values of the example.test types (test_service.hpp) and pack/unpack shortcuts.
#pragma once

#include <catch2/catch.hpp>

#include "core/value/pack_value.hpp"
#include "core/value/test_service.hpp"

namespace rr::testing {

inline constexpr std::string_view kSvc = "example.test";

inline Value vec3s(std::initializer_list<double> xyz) {
    return Value(NamedArray{"example.test.Vec3", NumericArray::from<double>(xyz), {}});
}

/// One example.test.Sample item: t, ids[3], tag[≤4], v (Vec3), vs (Vec3[2]), mat (double[2,2]).
inline std::vector<Value> sample_item(double t) {
    return {Value::scalar(t),
            Value::array<std::int32_t>({1, 2, 3}),
            Value::array<std::uint8_t>({7, 8}),
            vec3s({t, 0.5, -1}),
            vec3s({1, 2, 3, 4, 5, 6}),
            Value(MultiDimArray{{2, 2}, NumericArray::from<double>({1, 2, 3, 4})})};
}

inline PodArray samples(std::initializer_list<double> ts) {
    PodArray p{"example.test.Sample", {"t", "ids", "tag", "v", "vs", "mat"}};
    for (double t : ts) REQUIRE(p.push_back(sample_item(t)));
    return p;
}

inline Value inner(std::int32_t a, std::string s) {
    return Value(Structure{"example.test.Inner", {{"a", Value::scalar(a)}, {"s", Value(std::move(s))}}});
}

inline MessageElement pack_ok(const Value& v, std::string_view type, std::string_view name = "value") {
    auto r = pack_value(v, type_of(type), name, example_lookup(), kSvc);
    INFO((r ? std::string() : r.error().message));
    REQUIRE(r);
    return *r;
}

inline Value unpack_ok(const MessageElement& e, std::string_view type) {
    auto r = unpack_value(e, type_of(type), example_lookup(), kSvc);
    INFO((r ? std::string() : r.error().message));
    REQUIRE(r);
    return *r;
}

/// Packs, unpacks, and checks the value survived unchanged; returns the element.
inline MessageElement round_trip(const Value& v, std::string_view type) {
    MessageElement e = pack_ok(v, type);
    Value back = unpack_ok(e, type);
    CHECK(back == v);
    return e;
}

inline RRError pack_error(const Value& v, std::string_view type) {
    auto r = pack_value(v, type_of(type), "value", example_lookup(), kSvc);
    REQUIRE_FALSE(r);
    return r.error();
}

inline RRError unpack_error(const MessageElement& e, std::string_view type) {
    auto r = unpack_value(e, type_of(type), example_lookup(), kSvc);
    REQUIRE_FALSE(r);
    return r.error();
}

struct TypedValue {
    Value value;
    std::string type;
};

/// A few large values touching every kind (all strings ASCII, so truncation keeps them UTF-8).
inline std::vector<TypedValue> rich_values() {
    PodArray grid = samples({5, 6});
    grid.dims = {2, 1};
    PodArray pk{"example.test.Packet", {"s", "more", "grid", "n"}};
    REQUIRE(pk.push_back({Value(samples({1})), Value(samples({2})), Value(grid), Value::scalar<std::uint16_t>(9)}));
    MapString any;
    any.entries.emplace_back("p", Value(samples({1})));
    any.entries.emplace_back("l", Value(List{{inner(1, "a"), Value::array<double>({1, 2})}}));
    any.entries.emplace_back("m", Value(MultiDimArray{{2, 1}, NumericArray::from<std::int32_t>({1, 2})}));
    any.entries.emplace_back("n", Value(NamedArray{"example.test.Vec3", NumericArray::from<double>({1, 2, 3}), {1}}));
    Structure outer{"example.test.Outer", {}};
    outer.set("inner", inner(7, "seven"))
        .set("maybe", Value())
        .set("v", Value::array<double>({1, 2, 3}))
        .set("b", Value::array<double>({1}))
        .set("m", Value(MultiDimArray{{1, 2}, NumericArray::from<double>({9, 8})}))
        .set("fixed", Value(MultiDimArray{{2, 2}, NumericArray::from<std::int32_t>({1, 2, 3, 4})}))
        .set("names", Value(List{{Value("a")}}))
        .set("by_name", Value(MapString{{{"k", inner(1, "x")}}}))
        .set("any", Value(any))
        .set("color", Value(Enum{"example.test.Color", 5}))
        .set("c", Value::scalar(cdouble(0, -1)))
        .set("flag", Value::scalar(true))
        .set("bytes", Value::array<std::uint8_t>({0, 255}))
        .set("next", Value());
    return {{Value(outer), "Outer"}, {Value(pk), "Packet[]"}, {Value(any), "varvalue{string}"},
            {Value(samples({1, 2})), "Sample[2]"}};
}

/// A numeric element built by hand (for malformed inputs).
template <Numeric T>
MessageElement numeric_element(std::string name, std::initializer_list<T> items) {
    MessageElement e;
    e.name = std::move(name);
    e.type = numeric_type_v<T>;
    e.data = NumericArray::from<T>(items).to_bytes();
    return e;
}

}  // namespace rr::testing
