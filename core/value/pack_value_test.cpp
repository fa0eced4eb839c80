// pack → unpack round trips and exact element layouts (wire.md §3.2).
#include <catch2/catch.hpp>

#include <limits>

#include "core/value/test_values.hpp"
#include "core/value/var_type.hpp"

using namespace rr;
using namespace rr::testing;

namespace {

template <Numeric T>
void check_scalar_round_trip(T v, DataTypes code, std::size_t bytes) {
    MessageElement e = round_trip(Value::scalar(v), data_type_keyword(code));
    CHECK(e.name == "value");
    CHECK(e.type == code);
    CHECK(e.type_name.empty());
    CHECK_FALSE(e.number);
    CHECK(e.data.size() == bytes);
    CHECK(e.data_count() == 1);
}

std::vector<std::string> child_names(const MessageElement& e) {
    std::vector<std::string> n;
    for (const auto& c : e.elements) n.push_back(c.name);
    return n;
}

}  // namespace

TEST_CASE("pack: numeric scalars of every type are 1-item arrays") {
    check_scalar_round_trip<double>(-1.25, DataTypes::double_t, 8);
    check_scalar_round_trip<float>(3.5f, DataTypes::single_t, 4);
    check_scalar_round_trip<std::int8_t>(-128, DataTypes::int8_t, 1);
    check_scalar_round_trip<std::uint8_t>(255, DataTypes::uint8_t, 1);
    check_scalar_round_trip<std::int16_t>(-32768, DataTypes::int16_t, 2);
    check_scalar_round_trip<std::uint16_t>(65535, DataTypes::uint16_t, 2);
    check_scalar_round_trip<std::int32_t>(std::numeric_limits<std::int32_t>::min(), DataTypes::int32_t, 4);
    check_scalar_round_trip<std::uint32_t>(0xffffffffu, DataTypes::uint32_t, 4);
    check_scalar_round_trip<std::int64_t>(std::numeric_limits<std::int64_t>::min(), DataTypes::int64_t, 8);
    check_scalar_round_trip<std::uint64_t>(std::numeric_limits<std::uint64_t>::max(), DataTypes::uint64_t, 8);
    check_scalar_round_trip<cdouble>(cdouble(1.5, -2.5), DataTypes::cdouble_t, 16);
    check_scalar_round_trip<csingle>(csingle(0.25f, 8.0f), DataTypes::csingle_t, 8);
    check_scalar_round_trip<bool>(true, DataTypes::bool_t, 1);
}

TEST_CASE("pack: numeric data bytes are little-endian and shared, not copied") {
    Value v = Value::array<std::uint16_t>({0x0102, 0x0304});
    MessageElement e = pack_ok(v, "uint16[]");
    REQUIRE(e.data.size() == 4);
    CHECK(e.data.data()[0] == std::byte{0x02});
    CHECK(e.data.data()[1] == std::byte{0x01});
    CHECK(e.data.data() == reinterpret_cast<const std::byte*>(v.get_if<NumericArray>()->span<std::uint16_t>().data()));
    Value back = unpack_ok(e, "uint16[]");
    REQUIRE(back.get_if<NumericArray>());
    CHECK(back.get_if<NumericArray>()->is_view());
    CHECK(back.get_if<NumericArray>()->to_bytes().data() == e.data.data());
}

TEST_CASE("pack: arrays — variable, fixed [N] and bounded [N-]") {
    round_trip(Value::array<double>({}), "double[]");
    round_trip(Value::array<double>({1, 2, 3}), "double[3]");
    round_trip(Value::array<double>({1, 2}), "double[3-]");
    round_trip(Value::array<double>({}), "double[3-]");
    round_trip(Value::array<bool>({true, false, true}), "bool[]");
    round_trip(Value::array<cdouble>({cdouble(1, 2), cdouble(3, 4)}), "cdouble[2]");
    round_trip(Value::array<std::uint8_t>({1, 2, 3, 4, 5}), "uint8[0]");  // [0] behaves as []
}

TEST_CASE("pack: multi-dim arrays are 117 {dims:uint32, array} in column-major order") {
    Value m(MultiDimArray{{2, 3}, NumericArray::from<std::int32_t>({11, 21, 12, 22, 13, 23})});
    MessageElement e = round_trip(m, "int32[*]");
    CHECK(e.type == DataTypes::multidimarray_t);
    CHECK(e.type_name.empty());
    REQUIRE(e.elements.size() == 2);
    CHECK(e.elements[0].name == "dims");
    CHECK(e.elements[0].type == DataTypes::uint32_t);
    CHECK(e.elements[0].data_count() == 2);
    CHECK(e.elements[1].name == "array");
    CHECK(e.elements[1].type == DataTypes::int32_t);
    CHECK(e.elements[1].data_count() == 6);
    round_trip(m, "int32[2,3]");
    round_trip(Value(MultiDimArray{{4}, NumericArray::from<float>({1, 2, 3, 4})}), "single[4,]");
    round_trip(Value(MultiDimArray{{2, 0, 3}, NumericArray(DataTypes::bool_t)}), "bool[*]");
}

TEST_CASE("pack: strings are UTF-8 bytes, the empty string is type 11 with no data") {
    MessageElement e = round_trip(Value("h\xc3\xa9llo"), "string");
    CHECK(e.type == DataTypes::string_t);
    CHECK(e.data_count() == 6);
    MessageElement empty = round_trip(Value(""), "string");
    CHECK(empty.type == DataTypes::string_t);
    CHECK(empty.data_count() == 0);
}

TEST_CASE("pack: structs are 101 with the qualified name and fields in definition order") {
    Structure s{"example.test.Outer", {}};
    // Set fields out of order: packing writes definition order.
    s.set("next", Value())
        .set("bytes", Value::array<std::uint8_t>({1, 2}))
        .set("flag", Value::scalar(true))
        .set("c", Value::scalar(cdouble(0, 1)))
        .set("color", Value(Enum{"example.test.Color", 5}))
        .set("any", Value::array<double>({1.5}))
        .set("by_name", Value(MapString{{{"k1", inner(1, "x")}, {"k2", Value()}}}))
        .set("names", Value(List{{Value("a"), Value("b")}}))
        .set("fixed", Value(MultiDimArray{{2, 2}, NumericArray::from<std::int32_t>({1, 2, 3, 4})}))
        .set("m", Value(MultiDimArray{{1}, NumericArray::from<double>({9})}))
        .set("b", Value::array<double>({1}))
        .set("v", Value::array<double>({1, 2, 3}))
        .set("maybe", Value())
        .set("inner", inner(7, "seven"));
    Value v(std::move(s));
    MessageElement e = pack_ok(v, "Outer");
    CHECK(e.type == DataTypes::structure_t);
    CHECK(e.type_name == "example.test.Outer");
    CHECK(child_names(e) == std::vector<std::string>{"inner", "maybe", "v", "b", "m", "fixed", "names", "by_name",
                                                     "any", "color", "c", "flag", "bytes", "next"});
    const MessageElement* in = e.find("inner");
    REQUIRE(in);
    CHECK(in->type == DataTypes::structure_t);
    CHECK(in->type_name == "example.test.Inner");
    CHECK(e.find("maybe")->type == DataTypes::void_t);  // null struct field
    CHECK(e.find("next")->type == DataTypes::void_t);
    CHECK(e.find("color")->type == DataTypes::int32_t);
    CHECK(e.find("any")->type == DataTypes::double_t);

    Value back = unpack_ok(e, "example.test.Outer");
    // Unpacking yields definition order.
    auto* bs = back.get_if<Structure>();
    REQUIRE(bs);
    CHECK(bs->fields.front().name == "inner");
    for (const auto& f : v.get_if<Structure>()->fields) {
        INFO(f.name);
        REQUIRE(back.field(f.name));
        CHECK(*back.field(f.name) == f.value);
    }
}

TEST_CASE("pack: a struct may nest itself (recursive structs are nullable)") {
    auto outer = [](Value next) {
        Structure s{"example.test.Outer", {}};
        s.set("inner", Value()).set("maybe", Value()).set("v", Value::array<double>({0, 0, 0}))
            .set("b", Value::array<double>({})).set("m", Value(MultiDimArray{{0}, NumericArray()}))
            .set("fixed", Value(MultiDimArray{{2, 2}, NumericArray::zeros(DataTypes::int32_t, 4)}))
            .set("names", Value()).set("by_name", Value()).set("any", Value())
            .set("color", Value(Enum{"example.test.Color", 0})).set("c", Value::scalar(cdouble()))
            .set("flag", Value::scalar(false)).set("bytes", Value::array<std::uint8_t>({}))
            .set("next", std::move(next));
        return Value(std::move(s));
    };
    MessageElement e = round_trip(outer(outer(Value())), "Outer");
    CHECK(e.find("next")->type == DataTypes::structure_t);
    CHECK(e.find("next")->find("next")->type == DataTypes::void_t);
}

TEST_CASE("pack: unqualified names resolve in the service that defines the field") {
    Value w(Structure{"example.other.Wrapper",
                      {{"inner", inner(1, "i")}, {"local", Value(Structure{"example.other.Local", {{"k", Value::scalar<std::int8_t>(-1)}}})}}});
    auto e = pack_value(w, type_of("Wrapper"), "w", example_lookup(), "example.other");
    REQUIRE(e);
    CHECK(e->type_name == "example.other.Wrapper");
    CHECK(e->find("inner")->type_name == "example.test.Inner");
    CHECK(e->find("local")->type_name == "example.other.Local");
    auto back = unpack_value(*e, type_of("example.other.Wrapper"), example_lookup(), "example.test");
    REQUIRE(back);
    CHECK(*back == w);
}

TEST_CASE("pack: a struct value may leave its type name empty") {
    Value v(Structure{"", {{"a", Value::scalar<std::int32_t>(1)}, {"s", Value("x")}}});
    MessageElement e = pack_ok(v, "Inner");
    CHECK(e.type_name == "example.test.Inner");
}

TEST_CASE("pack: lists are 108 with children numbered 0..n-1") {
    Value l(List{{Value::array<double>({1}), Value::array<double>({2, 3})}});
    MessageElement e = round_trip(l, "double[]{list}");
    CHECK(e.type == DataTypes::list_t);
    REQUIRE(e.elements.size() == 2);
    CHECK(e.elements[0].number == 0);
    CHECK(e.elements[1].number == 1);
    CHECK(e.elements[1].name.empty());
    round_trip(Value(List{}), "string{list}");
    MessageElement null_list = round_trip(Value(), "int32{list}");
    CHECK(null_list.type == DataTypes::void_t);
    round_trip(Value(List{{inner(1, "a"), Value()}}), "Inner{list}");  // struct items may be null
}

TEST_CASE("pack: int32 maps are 102 numbered by key, string maps are 103 named by key") {
    MapInt32 m;
    m.entries.emplace_back(-5, Value("minus five"));
    m.entries.emplace_back(100, Value(""));
    MessageElement e = round_trip(Value(m), "string{int32}");
    CHECK(e.type == DataTypes::vector_t);
    CHECK(e.elements[0].number == -5);
    CHECK(e.elements[1].number == 100);

    MapString s;
    s.entries.emplace_back("zeta", Value::scalar<std::int32_t>(1));
    s.entries.emplace_back("alpha", Value::scalar<std::int32_t>(2));
    MessageElement es = round_trip(Value(s), "int32{string}");
    CHECK(es.type == DataTypes::dictionary_t);
    CHECK(child_names(es) == std::vector<std::string>{"zeta", "alpha"});  // order kept
    CHECK_FALSE(es.elements[0].number);
}

TEST_CASE("pack: enums travel as int32 scalars and unpack with their qualified name") {
    MessageElement e = round_trip(Value(Enum{"example.test.Color", 5}), "Color");
    CHECK(e.type == DataTypes::int32_t);
    CHECK(e.type_name.empty());
    CHECK(e.data_count() == 1);
    // A plain int32 scalar is accepted for an enum.
    MessageElement e2 = pack_ok(Value::scalar<std::int32_t>(1), "Color");
    CHECK(unpack_ok(e2, "Color") == Value(Enum{"example.test.Color", 1}));
    round_trip(Value(List{{Value(Enum{"example.test.Color", 0})}}), "Color{list}");
}

TEST_CASE("pack: a scalar pod is 110 with one 109 item numbered 0, fields in order") {
    MessageElement e = round_trip(Value(samples({0.5})), "Sample");
    CHECK(e.type == DataTypes::pod_array_t);
    CHECK(e.type_name == "example.test.Sample");
    REQUIRE(e.elements.size() == 1);
    const MessageElement& item = e.elements[0];
    CHECK(item.number == 0);
    CHECK(item.type == DataTypes::pod_t);
    CHECK(item.type_name.empty());
    CHECK(child_names(item) == std::vector<std::string>{"t", "ids", "tag", "v", "vs", "mat"});
    CHECK(item.find("t")->type == DataTypes::double_t);
    CHECK(item.find("ids")->data_count() == 3);
    CHECK(item.find("tag")->type == DataTypes::uint8_t);
    CHECK(item.find("tag")->data_count() == 2);  // bounded field: only the items present
    const MessageElement* v = item.find("v");
    CHECK(v->type == DataTypes::namedarray_array_t);
    CHECK(v->type_name == "example.test.Vec3");
    REQUIRE(v->elements.size() == 1);
    CHECK(v->elements[0].name == "array");
    CHECK(v->elements[0].data_count() == 3);
    CHECK(item.find("vs")->elements[0].data_count() == 6);
    // A fixed multi-dim field travels flattened (CORE pod_field_array), not as 117.
    CHECK(item.find("mat")->type == DataTypes::double_t);
    CHECK(item.find("mat")->data_count() == 4);
}

TEST_CASE("pack: pod arrays, fixed and multi-dim pod arrays") {
    MessageElement e = round_trip(Value(samples({1, 2, 3})), "Sample[]");
    REQUIRE(e.elements.size() == 3);
    CHECK(e.elements[2].number == 2);
    round_trip(Value(samples({1, 2})), "Sample[2]");
    round_trip(Value(samples({})), "Sample[]");

    PodArray grid = samples({1, 2, 3, 4, 5, 6});
    grid.dims = {3, 2};
    MessageElement m = round_trip(Value(grid), "Sample[*]");
    CHECK(m.type == DataTypes::pod_multidimarray_t);
    CHECK(m.type_name == "example.test.Sample");
    REQUIRE(m.elements.size() == 2);
    CHECK(m.elements[0].name == "dims");
    CHECK(m.elements[1].name == "array");
    CHECK(m.elements[1].type == DataTypes::pod_array_t);
    CHECK(m.elements[1].type_name == "example.test.Sample");
    CHECK(m.elements[1].elements.size() == 6);
    round_trip(Value(grid), "Sample[3,2]");
}

TEST_CASE("pack: pods nest pods, bounded pod arrays and multi-dim pod fields") {
    PodArray grid = samples({5, 6});
    grid.dims = {2, 1};
    PodArray pk{"example.test.Packet", {"s", "more", "grid", "n"}};
    REQUIRE(pk.push_back({Value(samples({1})), Value(samples({2})), Value(grid), Value::scalar<std::uint16_t>(9)}));
    REQUIRE(pk.push_back({Value(samples({3})), Value(samples({})), Value(grid), Value::scalar<std::uint16_t>(10)}));
    MessageElement e = round_trip(Value(pk), "Packet[]");
    const MessageElement& item = e.elements[0];
    CHECK(item.find("s")->type == DataTypes::pod_array_t);
    CHECK(item.find("s")->elements.size() == 1);
    CHECK(item.find("more")->elements.size() == 1);
    CHECK(e.elements[1].find("more")->elements.size() == 0);
    CHECK(item.find("grid")->type == DataTypes::pod_array_t);  // flattened: 110 with 2 items, no 111
    CHECK(item.find("grid")->elements.size() == 2);
}

TEST_CASE("pack: namedarrays are 115 {array: flat numbers}, multi-dim is 116") {
    MessageElement e = round_trip(vec3s({1, 2, 3}), "Vec3");
    CHECK(e.type == DataTypes::namedarray_array_t);
    CHECK(e.type_name == "example.test.Vec3");
    REQUIRE(e.elements.size() == 1);
    CHECK(e.elements[0].name == "array");
    CHECK(e.elements[0].type == DataTypes::double_t);
    CHECK(e.elements[0].data_count() == 3);
    round_trip(vec3s({1, 2, 3, 4, 5, 6}), "Vec3[]");
    round_trip(vec3s({1, 2, 3, 4, 5, 6}), "Vec3[2]");
    round_trip(vec3s({}), "Vec3[]");

    Value grid(NamedArray{"example.test.Vec3", NumericArray::from<double>({1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12}), {2, 2}});
    MessageElement m = round_trip(grid, "Vec3[*]");
    CHECK(m.type == DataTypes::namedarray_multidimarray_t);
    CHECK(m.type_name == "example.test.Vec3");
    CHECK(m.elements[0].name == "dims");
    CHECK(m.elements[1].name == "array");
    CHECK(m.elements[1].type == DataTypes::namedarray_array_t);
    CHECK(m.elements[1].type_name == "example.test.Vec3");
    CHECK(m.elements[1].elements[0].data_count() == 12);
    round_trip(grid, "Vec3[2,2]");

    // Nested namedarray: Pose = Vec3 + double[4] = 7 doubles per item.
    Value pose(NamedArray{"example.test.Pose", NumericArray::from<double>({1, 2, 3, 0, 0, 0, 1}), {}});
    MessageElement p = round_trip(pose, "Pose");
    CHECK(p.elements[0].data_count() == 7);
}

TEST_CASE("pack: struct fields of every pod/namedarray form") {
    PodArray cube = samples({1, 2, 3, 4});
    cube.dims = {2, 2, 1};
    PodArray pk{"example.test.Packet", {"s", "more", "grid", "n"}};
    PodArray grid = samples({5, 6});
    grid.dims = {2, 1};
    REQUIRE(pk.push_back({Value(samples({1})), Value(samples({2, 3})), Value(grid), Value::scalar<std::uint16_t>(9)}));
    Structure h{"example.test.Holder", {}};
    h.set("one", Value(samples({1})))
        .set("many", Value(samples({1, 2, 3})))
        .set("pair", Value(samples({1, 2})))
        .set("cube", Value(cube))
        .set("p", vec3s({1, 2, 3}))
        .set("ps", vec3s({}))
        .set("pgrid", Value(NamedArray{"example.test.Vec3", NumericArray::from<double>({1, 2, 3}), {1, 1}}))
        .set("pose", Value(NamedArray{"example.test.Pose", NumericArray::from<double>({1, 2, 3, 4, 5, 6, 7}), {}}))
        .set("pk", Value(pk));
    MessageElement e = round_trip(Value(h), "Holder");
    CHECK(e.find("cube")->type == DataTypes::pod_multidimarray_t);
    CHECK(e.find("pgrid")->type == DataTypes::namedarray_multidimarray_t);
}

TEST_CASE("pack: varvalue travels as the concrete type, unpack restores value and type string") {
    struct Case {
        Value v;
        DataTypes code;
        const char* type;
    };
    PodArray grid = samples({1, 2});
    grid.dims = {1, 2};
    MapString ms;
    ms.entries.emplace_back("a", Value::array<std::int32_t>({1}));
    ms.entries.emplace_back("b", Value(List{{Value("x"), Value()}}));
    MapInt32 mi;
    mi.entries.emplace_back(3, Value("three"));
    std::vector<Case> cases;
    cases.push_back({Value::array<double>({1, 2}), DataTypes::double_t, "double[]"});
    cases.push_back({Value::array<std::uint8_t>({}), DataTypes::uint8_t, "uint8[]"});
    cases.push_back({Value::array<cdouble>({cdouble(1, 2)}), DataTypes::cdouble_t, "cdouble[]"});
    cases.push_back({Value("text"), DataTypes::string_t, "string"});
    cases.push_back({Value(MultiDimArray{{2, 1}, NumericArray::from<std::int32_t>({1, 2})}), DataTypes::multidimarray_t, "int32[*]"});
    cases.push_back({inner(1, "x"), DataTypes::structure_t, "example.test.Inner"});
    cases.push_back({Value(samples({1})), DataTypes::pod_array_t, "example.test.Sample[]"});
    cases.push_back({Value(grid), DataTypes::pod_multidimarray_t, "example.test.Sample[*]"});
    cases.push_back({vec3s({1, 2, 3, 4, 5, 6}), DataTypes::namedarray_array_t, "example.test.Vec3[]"});
    cases.push_back({Value(NamedArray{"example.test.Vec3", NumericArray::from<double>({1, 2, 3}), {1}}),
                     DataTypes::namedarray_multidimarray_t, "example.test.Vec3[*]"});
    cases.push_back({Value(List{{Value::array<double>({1}), Value("s")}}), DataTypes::list_t, "varvalue{list}"});
    cases.push_back({Value(mi), DataTypes::vector_t, "varvalue{int32}"});
    cases.push_back({Value(ms), DataTypes::dictionary_t, "varvalue{string}"});
    cases.push_back({Value(), DataTypes::void_t, ""});
    for (const auto& c : cases) {
        INFO(c.type);
        CHECK(var_type_string(c.v) == c.type);
        MessageElement e = round_trip(c.v, "varvalue");
        CHECK(e.type == c.code);
    }
    // Enums and scalars lose what only the robdef knew: they come back as int32[] / T[].
    MessageElement e = pack_ok(Value(Enum{"example.test.Color", 5}), "varvalue");
    CHECK(e.type == DataTypes::int32_t);
    CHECK(unpack_ok(e, "varvalue") == Value::array<std::int32_t>({5}));
    CHECK(var_type_string(unpack_ok(pack_ok(Value::scalar(2.0), "varvalue"), "varvalue")) == "double[]");
    // varvalue{string}: a 103 whose children are varvalues of any type.
    round_trip(Value(ms), "varvalue{string}");
}

TEST_CASE("pack: varvalue struct fields are typed by their definition") {
    Structure s{"example.test.Inner", {{"a", Value::scalar<std::int32_t>(1)}, {"s", Value("x")}}};
    MessageElement e = pack_ok(Value(s), "varvalue");
    Value back = unpack_ok(e, "varvalue");
    CHECK(back == Value(s));  // `a` is a scalar again, because the definition says so
}
