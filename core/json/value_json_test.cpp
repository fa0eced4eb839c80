// value ↔ JSON round trips for every kind, and JSON errors (each asserting the error type).
// The per-rule examples live in docs/json-mapping.md (json_mapping_doc_test.cpp); these tests cover
// the larger values of core/value's test service and the Value → JSON direction's own errors.
#include <catch2/catch.hpp>

#include <cstring>
#include <limits>

#include "core/json/value_json.hpp"
#include "core/value/test_values.hpp"

using namespace rr;
using namespace rr::testing;
using nlohmann::json;

namespace {

json to_json_ok(const Value& v, std::string_view type) {
    auto j = value_to_json(v, type_of(type), example_lookup(), kSvc);
    INFO((j ? std::string() : j.error().message));
    REQUIRE(j);
    return *j;
}

Value from_json_ok(const json& j, std::string_view type) {
    auto v = value_from_json(j, type_of(type), example_lookup(), kSvc);
    INFO((v ? std::string() : v.error().message));
    REQUIRE(v);
    return *v;
}

/// Value → JSON text → Value must give back the value; returns the JSON.
json json_round_trip(const Value& v, std::string_view type) {
    json j = to_json_ok(v, type);
    Value back = from_json_ok(json::parse(j.dump()), type);
    CHECK(back == v);
    return j;
}

RRError from_json_error(const json& j, std::string_view type) {
    auto v = value_from_json(j, type_of(type), example_lookup(), kSvc);
    REQUIRE_FALSE(v);
    return v.error();
}

RRError to_json_error(const Value& v, std::string_view type) {
    auto j = value_to_json(v, type_of(type), example_lookup(), kSvc);
    REQUIRE_FALSE(j);
    return j.error();
}

Value outer_value() {
    Structure s{"example.test.Outer", {}};
    MapString by_name;
    by_name.entries.emplace_back("k1", inner(1, "x"));
    by_name.entries.emplace_back("k2", Value());
    s.set("inner", inner(7, "seven"))
        .set("maybe", Value())
        .set("v", Value::array<double>({1, 2, 3}))
        .set("b", Value::array<double>({1}))
        .set("m", Value(MultiDimArray{{1, 2}, NumericArray::from<double>({9, 8})}))
        .set("fixed", Value(MultiDimArray{{2, 2}, NumericArray::from<std::int32_t>({1, 2, 3, 4})}))
        .set("names", Value(List{{Value("a"), Value("")}}))
        .set("by_name", Value(by_name))
        .set("any", Value(List{{Value::array<std::uint64_t>({std::numeric_limits<std::uint64_t>::max()}), Value()}}))
        .set("color", Value(Enum{"example.test.Color", 5}))
        .set("c", Value::scalar(cdouble(0, -1)))
        .set("flag", Value::scalar(true))
        .set("bytes", Value::array<std::uint8_t>({0, 255}))
        .set("next", Value());
    return Value(std::move(s));
}

}  // namespace

TEST_CASE("json: numeric scalars and arrays of every type, extremes included") {
    using L64 = std::numeric_limits<std::int64_t>;
    using U64 = std::numeric_limits<std::uint64_t>;
    json_round_trip(Value::scalar<std::int64_t>(L64::min()), "int64");
    json_round_trip(Value::scalar<std::int64_t>(L64::max()), "int64");
    json_round_trip(Value::scalar<std::uint64_t>(U64::max()), "uint64");
    json_round_trip(Value::array<std::int64_t>({L64::min(), -9007199254740993, -9007199254740992, 0, 9007199254740992,
                                                 9007199254740993, L64::max()}),
                    "int64[]");
    CHECK(to_json_ok(Value::array<std::int64_t>({-9007199254740993, 9007199254740992}), "int64[]") ==
          json::parse(R"(["-9007199254740993", 9007199254740992])"));
    json_round_trip(Value::array<std::uint64_t>({0, 9007199254740993u, U64::max()}), "uint64[]");
    json_round_trip(Value::array<std::int8_t>({-128, 127}), "int8[]");
    json_round_trip(Value::array<std::uint8_t>({0, 255}), "uint8[2]");
    json_round_trip(Value::array<std::int16_t>({-32768, 32767}), "int16[]");
    json_round_trip(Value::array<std::uint16_t>({65535}), "uint16[]");
    json_round_trip(Value::array<std::int32_t>({std::numeric_limits<std::int32_t>::min()}), "int32[]");
    json_round_trip(Value::array<std::uint32_t>({0xffffffffu}), "uint32[]");
    json_round_trip(Value::array<double>({std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
                                          -std::numeric_limits<double>::infinity(), -0.0, 5e-324,
                                          std::numeric_limits<double>::max()}),
                    "double[]");
    json_round_trip(Value::array<float>({std::numeric_limits<float>::quiet_NaN(), -std::numeric_limits<float>::infinity(),
                                         1e-45f, std::numeric_limits<float>::max(), 0.1f}),
                    "single[]");
    json_round_trip(Value::array<cdouble>({cdouble(1, -1), cdouble(std::numeric_limits<double>::infinity(), 0)}),
                    "cdouble[]");
    json_round_trip(Value::scalar(csingle(0.5f, 2)), "csingle");
    json_round_trip(Value::array<bool>({true, false}), "bool[]");
    json_round_trip(Value::scalar(false), "bool");
    // Empty arrays of every kind.
    for (const char* t : {"double[]", "single[]", "int8[]", "uint8[]", "int16[]", "uint16[]", "int32[]", "uint32[]",
                          "int64[]", "uint64[]", "cdouble[]", "csingle[]", "bool[]"}) {
        INFO(t);
        auto type = type_of(t);
        Value empty(NumericArray(type.base));
        CHECK(json_round_trip(empty, t) == json::array());
    }
    json_round_trip(Value(MultiDimArray{{0}, NumericArray(DataTypes::int32_t)}), "int32[*]");
}

TEST_CASE("json: scalars are JSON values, arrays JSON arrays") {
    CHECK(to_json_ok(Value::scalar(2.5), "double") == json(2.5));
    CHECK(to_json_ok(Value::array<double>({2.5}), "double[]") == json::parse("[2.5]"));
    CHECK(to_json_ok(Value::scalar(cdouble(1, 2)), "cdouble") == json::parse(R"({"re":1.0,"im":2.0})"));
}

TEST_CASE("json: strings, including invalid UTF-8 from the wire") {
    json_round_trip(Value("h\xc3\xa9llo \xf0\x9f\x98\x80"), "string");
    json_round_trip(Value(""), "string");
    CHECK(to_json_error(Value("bad \xff"), "string").type == MessageErrorType::DataTypeError);
    MapString m;
    m.entries.emplace_back("\xc0\xaf", Value("x"));
    CHECK(to_json_error(Value(m), "string{string}").type == MessageErrorType::DataTypeError);
}

TEST_CASE("json: a struct with every kind of field") {
    Value v = outer_value();
    json j = json_round_trip(v, "Outer");
    CHECK(j["maybe"].is_null());
    CHECK(j["color"] == json(5));
    CHECK(j["fixed"] == json::parse(R"({"dims":[2,2],"array":[1,2,3,4]})"));
    CHECK(j["any"] == json::parse(R"({"type":"varvalue{list}","value":[{"type":"uint64[]","value":["18446744073709551615"]},null]})"));
    CHECK(j["by_name"]["k2"].is_null());
    // Through the wire too: JSON → value → element → value → JSON.
    Value from = from_json_ok(j, "Outer");
    MessageElement e = pack_ok(from, "Outer");
    CHECK(to_json_ok(unpack_ok(e, "Outer"), "Outer") == j);
}

TEST_CASE("json: pods, pod arrays, multi-dim pods and nested pods") {
    json one = json_round_trip(Value(samples({0.5})), "Sample");
    CHECK(one == json::parse(R"({"t":0.5,"ids":[1,2,3],"tag":[7,8],"v":{"x":0.5,"y":0.5,"z":-1.0},
        "vs":[{"x":1.0,"y":2.0,"z":3.0},{"x":4.0,"y":5.0,"z":6.0}],"mat":{"dims":[2,2],"array":[1.0,2.0,3.0,4.0]}})"));
    CHECK(json_round_trip(Value(samples({1, 2, 3})), "Sample[]").size() == 3);
    PodArray grid = samples({1, 2, 3, 4, 5, 6});
    grid.dims = {3, 2};
    json g = json_round_trip(Value(grid), "Sample[3,2]");
    CHECK(g["dims"] == json::parse("[3,2]"));
    CHECK(g["array"].size() == 6);

    PodArray pg = samples({5, 6});
    pg.dims = {2, 1};
    PodArray pk{"example.test.Packet", {"s", "more", "grid", "n"}};
    REQUIRE(pk.push_back({Value(samples({1})), Value(samples({2})), Value(pg), Value::scalar<std::uint16_t>(9)}));
    json p = json_round_trip(Value(pk), "Packet");
    CHECK(p["s"].is_object());
    CHECK(p["more"].is_array());
    CHECK(p["grid"]["dims"] == json::parse("[2,1]"));
    CHECK(p["n"] == json(9));
}

TEST_CASE("json: namedarrays as objects of fields") {
    CHECK(json_round_trip(vec3s({1, 2, 3}), "Vec3") == json::parse(R"({"x":1.0,"y":2.0,"z":3.0})"));
    CHECK(json_round_trip(vec3s({1, 2, 3, 4, 5, 6}), "Vec3[]").size() == 2);
    Value pose(NamedArray{"example.test.Pose", NumericArray::from<double>({1, 2, 3, 0.5, 0.5, 0.5, 0.5}), {}});
    CHECK(json_round_trip(pose, "Pose") ==
          json::parse(R"({"position":{"x":1.0,"y":2.0,"z":3.0},"orientation":[0.5,0.5,0.5,0.5]})"));
    Value grid(NamedArray{"example.test.Vec3", NumericArray::from<double>({1, 2, 3, 4, 5, 6}), {1, 2}});
    CHECK(json_round_trip(grid, "Vec3[*]")["dims"] == json::parse("[1,2]"));
    CHECK(json_round_trip(vec3s({}), "Vec3[]") == json::array());
}

TEST_CASE("json: the Holder struct (every pod/namedarray field form) survives JSON and the wire") {
    PodArray cube = samples({1, 2, 3, 4});
    cube.dims = {2, 2, 1};
    PodArray pg = samples({5, 6});
    pg.dims = {2, 1};
    PodArray pk{"example.test.Packet", {"s", "more", "grid", "n"}};
    REQUIRE(pk.push_back({Value(samples({1})), Value(samples({2, 3})), Value(pg), Value::scalar<std::uint16_t>(9)}));
    Structure h{"example.test.Holder", {}};
    h.set("one", Value(samples({1})))
        .set("many", Value(samples({})))
        .set("pair", Value(samples({1, 2})))
        .set("cube", Value(cube))
        .set("p", vec3s({1, 2, 3}))
        .set("ps", vec3s({1, 2, 3, 4, 5, 6}))
        .set("pgrid", Value(NamedArray{"example.test.Vec3", NumericArray::from<double>({1, 2, 3}), {1, 1}}))
        .set("pose", Value(NamedArray{"example.test.Pose", NumericArray::from<double>({1, 2, 3, 4, 5, 6, 7}), {}}))
        .set("pk", Value(pk));
    json j = json_round_trip(Value(h), "Holder");
    Value from = from_json_ok(j, "Holder");
    CHECK(to_json_ok(unpack_ok(pack_ok(from, "Holder"), "Holder"), "Holder") == j);
}

TEST_CASE("json: containers") {
    MapInt32 m;
    m.entries.emplace_back(-3, Value("a"));
    m.entries.emplace_back(2, Value("b"));
    m.entries.emplace_back(10, Value("c"));
    CHECK(json_round_trip(Value(m), "string{int32}") == json::parse(R"({"-3":"a","2":"b","10":"c"})"));
    // Read back in numeric key order whatever the order of the text.
    Value back = from_json_ok(json::parse(R"({"10":"c","-3":"a","2":"b"})"), "string{int32}");
    CHECK(back == Value(m));
    MapString s;
    s.entries.emplace_back("a", Value::array<double>({1}));
    json_round_trip(Value(s), "double[]{string}");
    json_round_trip(Value(List{{inner(1, "a"), Value()}}), "Inner{list}");
    json_round_trip(Value(), "Inner{list}");
    json_round_trip(Value(List{}), "double{list}");
    json_round_trip(Value(MapInt32{}), "double{int32}");
}

TEST_CASE("json: varvalue of every kind") {
    PodArray grid = samples({1, 2});
    grid.dims = {1, 2};
    MapInt32 mi;
    mi.entries.emplace_back(1, Value("x"));
    for (const Value& v : {Value(), Value::array<double>({1.5}), Value("s"),
                           Value(MultiDimArray{{2}, NumericArray::from<std::int8_t>({1, 2})}), inner(1, "x"),
                           Value(samples({1})), Value(grid), vec3s({1, 2, 3}),
                           Value(NamedArray{"example.test.Vec3", NumericArray::from<double>({1, 2, 3}), {1}}),
                           Value(List{{Value("a"), Value()}}), Value(mi),
                           Value(MapString{{{"k", Value::array<bool>({true})}}}), Value(Enum{"example.test.Color", 1})}) {
        INFO(var_type_string(v));
        json j = json_round_trip(v, "varvalue");
        if (v.is_null())
            CHECK(j.is_null());
        else
            CHECK(j["type"] == json(var_type_string(v)));
    }
}

TEST_CASE("json errors: wrong JSON kind is DataTypeMismatch") {
    CHECK(from_json_error(json("1"), "double").type == MessageErrorType::DataTypeMismatch);
    CHECK(from_json_error(json(1), "string").type == MessageErrorType::DataTypeMismatch);
    CHECK(from_json_error(json::object(), "double[]").type == MessageErrorType::DataTypeMismatch);
    CHECK(from_json_error(json::array(), "Inner").type == MessageErrorType::DataTypeMismatch);
    CHECK(from_json_error(json::array(), "Vec3").type == MessageErrorType::DataTypeMismatch);
    CHECK(from_json_error(json::object(), "Sample[]").type == MessageErrorType::DataTypeMismatch);
    CHECK(from_json_error(json::parse("[1]"), "Vec3[]").type == MessageErrorType::DataTypeMismatch);
    CHECK(from_json_error(json(true), "Color").type == MessageErrorType::DataTypeMismatch);
    CHECK(from_json_error(json(1), "void").type == MessageErrorType::DataTypeMismatch);
}

TEST_CASE("json errors: out-of-range integers are OutOfRange, with the path") {
    auto e = from_json_error(json::parse("[1, 2, 300]"), "uint8[]");
    CHECK(e.type == MessageErrorType::OutOfRange);
    CHECK(e.message.find("value[2]") != std::string::npos);
    CHECK(from_json_error(json(-129), "int8").type == MessageErrorType::OutOfRange);
    CHECK(from_json_error(json(65536), "uint16").type == MessageErrorType::OutOfRange);
    CHECK(from_json_error(json("18446744073709551616"), "uint64").type == MessageErrorType::OutOfRange);
    json pod = to_json_ok(Value(samples({1})), "Sample");
    pod["ids"][1] = 1e10;
    auto pe = from_json_error(pod, "Sample");
    CHECK(pe.type == MessageErrorType::OutOfRange);
    CHECK(pe.message.find("value.ids[1]") != std::string::npos);
    json vec = json::parse(R"({"x":1,"y":"big","z":3})");
    CHECK(from_json_error(vec, "Vec3").type == MessageErrorType::DataTypeMismatch);
}

TEST_CASE("json errors: enum names") {
    CHECK(from_json_ok(json("blue"), "Color") == Value(Enum{"example.test.Color", 5}));
    CHECK(from_json_ok(json(42), "Color") == Value(Enum{"example.test.Color", 42}));
    auto e = from_json_error(json("purple"), "Color");
    CHECK(e.type == MessageErrorType::InvalidArgument);
    CHECK(e.message.find("purple") != std::string::npos);
    CHECK(from_json_error(json("Blue"), "Color").type == MessageErrorType::InvalidArgument);
    CHECK(from_json_error(json(nullptr), "Color").type == MessageErrorType::NullValue);
}

TEST_CASE("json errors: lengths, fields, shapes, keys and nulls") {
    CHECK(from_json_error(json::parse("[1,2]"), "double[3]").type == MessageErrorType::DataTypeError);
    CHECK(from_json_error(json::parse("[1,2,3,4]"), "double[3-]").type == MessageErrorType::DataTypeError);
    CHECK(from_json_error(json::parse(R"({"dims":[2],"array":[1]})"), "double[*]").type == MessageErrorType::DataTypeError);
    CHECK(from_json_error(json::parse(R"({"dims":[],"array":[]})"), "double[*]").type == MessageErrorType::DataTypeError);
    CHECK(from_json_error(json::parse(R"({"array":[1]})"), "double[*]").type == MessageErrorType::DataTypeError);
    CHECK(from_json_error(json::parse(R"({"dims":[-1],"array":[]})"), "double[*]").type == MessageErrorType::OutOfRange);
    CHECK(from_json_error(json::parse(R"({"a":1})"), "Inner").type == MessageErrorType::DataTypeError);
    CHECK(from_json_error(json::parse(R"({"a":1,"s":"","t":2})"), "Inner").type == MessageErrorType::DataTypeError);
    CHECK(from_json_error(json::parse(R"({"x":1,"y":2})"), "Vec3").type == MessageErrorType::DataTypeError);
    CHECK(from_json_error(json::parse(R"({"x":1,"y":2,"z":3,"w":4})"), "Vec3").type == MessageErrorType::DataTypeError);
    CHECK(from_json_error(json::parse(R"({"position":{"x":1,"y":2,"z":3},"orientation":[1,2,3]})"), "Pose").type ==
          MessageErrorType::DataTypeError);
    CHECK(from_json_error(json::parse(R"([{"x":1,"y":2,"z":3}])"), "Vec3[2]").type == MessageErrorType::DataTypeError);
    CHECK(from_json_error(json::parse(R"({"+1":"x"})"), "string{int32}").type == MessageErrorType::DataTypeError);
    CHECK(from_json_error(json::parse(R"({"2147483648":"x"})"), "string{int32}").type == MessageErrorType::DataTypeError);
    CHECK(from_json_error(json::parse(R"({"-0":"x"})"), "string{int32}").type == MessageErrorType::DataTypeError);
    CHECK(from_json_error(json::parse(R"({"type":"double[]"})"), "varvalue").type == MessageErrorType::DataTypeError);
    CHECK(from_json_error(json::parse(R"({"type":"varvalue","value":null})"), "varvalue").type ==
          MessageErrorType::DataTypeError);
    CHECK(from_json_error(json::parse(R"({"type":"example.test.Nope","value":{}})"), "varvalue").type ==
          MessageErrorType::DataTypeError);
    for (const char* t : {"double", "int32[]", "double[*]", "string", "Sample", "Sample[]", "Vec3", "Vec3[*]"}) {
        INFO(t);
        CHECK(from_json_error(json(nullptr), t).type == MessageErrorType::NullValue);
    }
    json pod = to_json_ok(Value(samples({1})), "Sample");
    pod["mat"] = json::parse(R"({"dims":[4],"array":[1,2,3,4]})");
    CHECK(from_json_error(pod, "Sample").type == MessageErrorType::DataTypeError);
    pod.erase("mat");
    CHECK(from_json_error(pod, "Sample").type == MessageErrorType::DataTypeError);
}

TEST_CASE("json errors: value does not match the type (Value → JSON)") {
    CHECK(to_json_error(Value("x"), "double").type == MessageErrorType::DataTypeMismatch);
    CHECK(to_json_error(Value(), "double").type == MessageErrorType::NullValue);
    CHECK(to_json_error(Value::array<double>({1, 2}), "double").type == MessageErrorType::DataTypeError);
    CHECK(to_json_error(Value::array<double>({1, 2}), "double[3]").type == MessageErrorType::DataTypeError);
    CHECK(to_json_error(inner(1, "x"), "example.other.Local").type == MessageErrorType::DataTypeMismatch);
    CHECK(to_json_error(Value(Structure{"example.test.Inner", {{"a", Value::scalar<std::int32_t>(1)}}}), "Inner").type ==
          MessageErrorType::DataTypeError);
    CHECK(to_json_error(vec3s({1, 2}), "Vec3[]").type == MessageErrorType::DataTypeError);
    CHECK(to_json_error(Value(samples({1, 2})), "Sample").type == MessageErrorType::DataTypeError);
    MapInt32 dup;
    dup.entries.emplace_back(1, Value("a"));
    dup.entries.emplace_back(1, Value("b"));
    CHECK(to_json_error(Value(dup), "string{int32}").type == MessageErrorType::DataTypeError);
    CHECK(to_json_error(Value(Structure{"", {}}), "varvalue").type == MessageErrorType::DataTypeError);
}

TEST_CASE("json: nesting depth is limited both ways") {
    json deep = json::parse(R"({"type":"double[]","value":[1.0]})");
    for (int i = 0; i < 10; ++i) deep = json{{"type", "varvalue{list}"}, {"value", json::array({deep})}};
    Limits small;
    small.max_nesting_depth = 8;
    auto v = value_from_json(deep, type_of("varvalue"), example_lookup(), kSvc, small);
    REQUIRE_FALSE(v);
    CHECK(v.error().type == MessageErrorType::ProtocolError);
    Value ok = from_json_ok(deep, "varvalue");
    auto j = value_to_json(ok, type_of("varvalue"), example_lookup(), kSvc, small);
    REQUIRE_FALSE(j);
    CHECK(j.error().type == MessageErrorType::ProtocolError);

    // A hostile document far deeper than the limit fails cleanly.
    std::string text;
    for (int i = 0; i < 5000; ++i) text += R"({"type":"varvalue{list}","value":[)";
    text += "null";
    for (int i = 0; i < 5000; ++i) text += "]}";
    auto h = value_from_json(json::parse(text), type_of("varvalue"), example_lookup(), kSvc);
    REQUIRE_FALSE(h);
    CHECK(h.error().type == MessageErrorType::ProtocolError);
}

TEST_CASE("json: with BinaryArrays, numeric arrays become {\"$binary\"} references to their bytes") {
    BinaryArrays bin;
    auto j = value_to_json(Value::array<double>({1.5, -2, 3}), type_of("double[]"), example_lookup(), kSvc, {}, &bin);
    REQUIRE(j);
    CHECK(*j == json{{"$binary", 0}, {"type", "double"}, {"length", 3}, {"offset", 0}});
    REQUIRE(bin.blobs.size() == 1);
    CHECK(bin.bytes == 24);
    REQUIRE(bin.blobs[0].size() == 24);
    double back[3];
    std::memcpy(back, bin.blobs[0].data(), 24);
    CHECK(back[0] == 1.5);
    CHECK(back[1] == -2);
    CHECK(back[2] == 3);

    // Scalars stay numbers, bool arrays stay JSON; the next reference takes the next index.
    j = value_to_json(Value::scalar(2.5), type_of("double"), example_lookup(), kSvc, {}, &bin);
    CHECK(*j == json(2.5));
    j = value_to_json(Value::array<bool>({true, false}), type_of("bool[]"), example_lookup(), kSvc, {}, &bin);
    CHECK(*j == json{true, false});
    j = value_to_json(Value::array<std::uint8_t>({}), type_of("uint8[]"), example_lookup(), kSvc, {}, &bin);
    CHECK(*j == json{{"$binary", 1}, {"type", "uint8"}, {"length", 0}, {"offset", 24}});
    j = value_to_json(Value::array<std::uint8_t>({1, 2, 3}), type_of("uint8[]"), example_lookup(), kSvc, {}, &bin);
    CHECK(*j == json{{"$binary", 2}, {"type", "uint8"}, {"length", 3}, {"offset", 24}});
    j = value_to_json(Value::array<std::int16_t>({-1}), type_of("int16[]"), example_lookup(), kSvc, {}, &bin);
    CHECK(*j == json{{"$binary", 3}, {"type", "int16"}, {"length", 1}, {"offset", 32}});  // 3 bytes padded to 8
    CHECK(bin.blobs.size() == 4);
    CHECK(bin.bytes == 40);

    // Inside a struct: the vector and the multi-dim fields, the rest as in the text form.
    BinaryArrays in_struct;
    auto outer = value_to_json(rich_values()[0].value, type_of("Outer"), example_lookup(), kSvc, {}, &in_struct);
    REQUIRE(outer);
    auto text = to_json_ok(rich_values()[0].value, "Outer");
    CHECK((*outer)["v"] == json{{"$binary", 0}, {"type", "double"}, {"length", 3}, {"offset", 0}});
    CHECK((*outer)["m"]["dims"] == text["m"]["dims"]);
    CHECK((*outer)["m"]["array"]["type"] == "double");
    CHECK((*outer)["inner"] == text["inner"]);
    CHECK((*outer)["flag"] == text["flag"]);
    CHECK(in_struct.blobs.size() >= 3);

    // A value that fails leaves no blobs behind.
    BinaryArrays failed;
    auto bad = value_to_json(Value("text"), type_of("double[]"), example_lookup(), kSvc, {}, &failed);
    CHECK_FALSE(bad);
    CHECK(failed.blobs.empty());
    CHECK(failed.bytes == 0);
}
