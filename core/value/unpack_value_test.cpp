// Errors of pack and unpack (each asserting the error type), untyped unpacking and limits.
#include <catch2/catch.hpp>

#include "core/value/test_values.hpp"
#include "core/value/var_type.hpp"

using namespace rr;
using namespace rr::testing;

namespace {

bool mentions(const RRError& e, std::string_view text) {
    return e.message.find(text) != std::string::npos;
}

MessageElement list_of(std::vector<MessageElement> children) {
    MessageElement e;
    e.type = DataTypes::list_t;
    e.elements = std::move(children);
    return e;
}

}  // namespace

TEST_CASE("pack errors: wrong kind or numeric type is DataTypeMismatch") {
    CHECK(pack_error(Value("1.5"), "double").type == MessageErrorType::DataTypeMismatch);
    CHECK(pack_error(Value::scalar<float>(1), "double").type == MessageErrorType::DataTypeMismatch);
    CHECK(pack_error(Value::array<double>({1}), "string").type == MessageErrorType::DataTypeMismatch);
    CHECK(pack_error(Value(List{}), "double{int32}").type == MessageErrorType::DataTypeMismatch);
    CHECK(pack_error(Value::array<double>({1, 2}), "double[*]").type == MessageErrorType::DataTypeMismatch);
    CHECK(pack_error(inner(1, "x"), "example.other.Local").type == MessageErrorType::DataTypeMismatch);
    CHECK(pack_error(Value(Enum{"example.test.Other", 1}), "Color").type == MessageErrorType::DataTypeMismatch);
    CHECK(pack_error(vec3s({1, 2, 3}), "Sample").type == MessageErrorType::DataTypeMismatch);
    CHECK(pack_error(Value(NamedArray{"example.test.Vec3", NumericArray::from<float>({1, 2, 3}), {}}), "Vec3").type ==
          MessageErrorType::DataTypeMismatch);
}

TEST_CASE("pack errors: wrong lengths are DataTypeError and name the path and the expected type") {
    auto scalar = pack_error(Value::array<double>({1, 2}), "double");
    CHECK(scalar.type == MessageErrorType::DataTypeError);
    auto fixed = pack_error(Value::array<double>({1, 2}), "double[3]");
    CHECK(fixed.type == MessageErrorType::DataTypeError);
    CHECK(mentions(fixed, "double[3]"));
    CHECK(mentions(fixed, "\"value\""));
    CHECK(pack_error(Value::array<double>({1, 2, 3, 4}), "double[3-]").type == MessageErrorType::DataTypeError);
    CHECK(pack_error(Value(MultiDimArray{{2, 2}, NumericArray::from<double>({1, 2, 3})}), "double[*]").type ==
          MessageErrorType::DataTypeError);
    CHECK(pack_error(Value(MultiDimArray{{4}, NumericArray::from<double>({1, 2, 3, 4})}), "double[2,2]").type ==
          MessageErrorType::DataTypeError);
    CHECK(pack_error(Value(samples({1, 2})), "Sample").type == MessageErrorType::DataTypeError);
    CHECK(pack_error(Value(samples({1, 2, 3})), "Sample[2]").type == MessageErrorType::DataTypeError);
    CHECK(pack_error(vec3s({1, 2, 3, 4}), "Vec3[]").type == MessageErrorType::DataTypeError);
    CHECK(pack_error(vec3s({1, 2, 3, 4, 5, 6}), "Vec3").type == MessageErrorType::DataTypeError);

    // Inside a pod: the field path is in the message.
    PodArray p = samples({1});
    *p.field(0, "ids") = Value::array<std::int32_t>({1, 2});
    auto in_pod = pack_error(Value(p), "Sample");
    CHECK(in_pod.type == MessageErrorType::DataTypeError);
    CHECK(mentions(in_pod, "value[0].ids"));
    PodArray q = samples({1});
    *q.field(0, "tag") = Value::array<std::uint8_t>({1, 2, 3, 4, 5});
    CHECK(pack_error(Value(q), "Sample").type == MessageErrorType::DataTypeError);
    PodArray r = samples({1});
    *r.field(0, "mat") = Value(MultiDimArray{{4, 1}, NumericArray::from<double>({1, 2, 3, 4})});
    CHECK(pack_error(Value(r), "Sample").type == MessageErrorType::DataTypeError);
}

TEST_CASE("pack errors: null where not nullable is NullValue") {
    for (const char* t : {"double", "int32[]", "double[*]", "string", "Color", "Sample", "Sample[]", "Vec3", "Vec3[*]"}) {
        INFO(t);
        CHECK(pack_error(Value(), t).type == MessageErrorType::NullValue);
    }
    // Nullable: structs, containers, varvalue.
    for (const char* t : {"Inner", "double{list}", "Inner{int32}", "string{string}", "varvalue", "varvalue{list}"}) {
        INFO(t);
        CHECK(pack_ok(Value(), t).type == DataTypes::void_t);
    }
    // Inside a list, a numeric item may not be null.
    CHECK(pack_error(Value(List{{Value()}}), "double{list}").type == MessageErrorType::NullValue);
}

TEST_CASE("pack errors: missing, unknown and duplicate fields, duplicate map keys") {
    Value missing(Structure{"example.test.Inner", {{"a", Value::scalar<std::int32_t>(1)}}});
    auto m = pack_error(missing, "Inner");
    CHECK(m.type == MessageErrorType::DataTypeError);
    CHECK(mentions(m, "value.s"));
    Value extra(Structure{"example.test.Inner",
                          {{"a", Value::scalar<std::int32_t>(1)}, {"s", Value("")}, {"zz", Value()}}});
    auto x = pack_error(extra, "Inner");
    CHECK(x.type == MessageErrorType::DataTypeError);
    CHECK(mentions(x, "zz"));
    PodArray p{"example.test.Sample", {"t"}};
    REQUIRE(p.push_back({Value::scalar(1.0)}));
    CHECK(pack_error(Value(p), "Sample").type == MessageErrorType::DataTypeError);

    MapInt32 mi;
    mi.entries.emplace_back(1, Value("a"));
    mi.entries.emplace_back(1, Value("b"));
    CHECK(pack_error(Value(mi), "string{int32}").type == MessageErrorType::DataTypeError);
    MapString ms;
    ms.entries.emplace_back("k", Value("a"));
    ms.entries.emplace_back("k", Value("b"));
    CHECK(pack_error(Value(ms), "string{string}").type == MessageErrorType::DataTypeError);
}

TEST_CASE("pack errors: unknown types and types that are not values") {
    CHECK(pack_error(Value(), "NoSuchType").type == MessageErrorType::DataTypeError);
    CHECK(pack_error(Value(Structure{"example.test.Nope", {}}), "varvalue").type == MessageErrorType::DataTypeError);
    CHECK(pack_error(Value(Structure{"", {}}), "varvalue").type == MessageErrorType::DataTypeError);
    robdef::TypeDefinition gen = type_of("double");
    gen.container = robdef::ContainerKind::generator;
    auto r = pack_value(Value::scalar(1.0), gen, "g", example_lookup(), kSvc);
    REQUIRE_FALSE(r);
    CHECK(r.error().type == MessageErrorType::DataTypeError);
}

TEST_CASE("unpack errors: wrong element type is DataTypeMismatch, null is NullValue") {
    MessageElement d = numeric_element<double>("x", {1.0});
    CHECK(unpack_error(d, "single").type == MessageErrorType::DataTypeMismatch);
    CHECK(unpack_error(d, "string").type == MessageErrorType::DataTypeMismatch);
    CHECK(unpack_error(d, "Inner").type == MessageErrorType::DataTypeMismatch);
    CHECK(unpack_error(d, "double{list}").type == MessageErrorType::DataTypeMismatch);
    CHECK(unpack_error(d, "double[*]").type == MessageErrorType::DataTypeMismatch);
    CHECK(unpack_error(pack_ok(inner(1, "x"), "Inner"), "example.other.Local").type ==
          MessageErrorType::DataTypeMismatch);
    MessageElement wrong_name = pack_ok(vec3s({1, 2, 3}), "Vec3");
    wrong_name.type_name = "example.test.Pose";
    CHECK(unpack_error(wrong_name, "Vec3").type == MessageErrorType::DataTypeMismatch);

    MessageElement null;
    for (const char* t : {"double", "uint8[]", "double[*]", "string", "Color", "Sample", "Vec3"}) {
        INFO(t);
        CHECK(unpack_error(null, t).type == MessageErrorType::NullValue);
    }
    for (const char* t : {"Inner", "double{list}", "varvalue", "void"}) {
        INFO(t);
        CHECK(unpack_ok(null, t).is_null());
    }
}

TEST_CASE("unpack errors: lengths, numbering, missing children") {
    CHECK(unpack_error(numeric_element<double>("x", {1, 2}), "double").type == MessageErrorType::DataTypeError);
    CHECK(unpack_error(numeric_element<double>("x", {1, 2}), "double[3]").type == MessageErrorType::DataTypeError);
    CHECK(unpack_error(numeric_element<double>("x", {1, 2, 3, 4}), "double[3-]").type ==
          MessageErrorType::DataTypeError);
    CHECK(unpack_error(numeric_element<std::int32_t>("x", {1, 2}), "Color").type == MessageErrorType::DataTypeError);

    // Ragged bytes (not a whole number of items).
    MessageElement ragged = numeric_element<std::uint8_t>("x", {1, 2, 3});
    ragged.type = DataTypes::uint16_t;
    CHECK(unpack_error(ragged, "uint16[]").type == MessageErrorType::DataTypeError);

    // Lists must be numbered 0..n-1 in order.
    auto a = numeric_element<double>("", {1});
    auto b = numeric_element<double>("", {2});
    a.number = 0;
    b.number = 2;
    CHECK(unpack_error(list_of({a, b}), "double{list}").type == MessageErrorType::DataTypeError);
    b.number = 1;
    CHECK(unpack_ok(list_of({a, b}), "double{list}") == Value(List{{Value::scalar(1.0), Value::scalar(2.0)}}));
    CHECK(unpack_error(list_of({b, a}), "double{list}").type == MessageErrorType::DataTypeError);
    // A v2-style decimal name works as a number.
    a.number.reset();
    a.name = "0";
    CHECK(unpack_ok(list_of({a}), "double{list}") == Value(List{{Value::scalar(1.0)}}));
    a.name = "zero";
    CHECK(unpack_error(list_of({a}), "double{list}").type == MessageErrorType::DataTypeError);

    // Duplicate map keys.
    MessageElement m;
    m.type = DataTypes::vector_t;
    auto k1 = numeric_element<double>("", {1});
    k1.number = 4;
    m.elements = {k1, k1};
    CHECK(unpack_error(m, "double{int32}").type == MessageErrorType::DataTypeError);
    MessageElement s;
    s.type = DataTypes::dictionary_t;
    s.elements = {numeric_element<double>("k", {1}), numeric_element<double>("k", {2})};
    CHECK(unpack_error(s, "double{string}").type == MessageErrorType::DataTypeError);

    // Missing struct field.
    MessageElement st = pack_ok(inner(1, "x"), "Inner");
    st.elements.pop_back();
    auto missing = unpack_error(st, "Inner");
    CHECK(missing.type == MessageErrorType::MessageElementNotFound);
    CHECK(mentions(missing, "value.s"));
    // Extra fields are ignored, order is free.
    MessageElement st2 = pack_ok(inner(1, "x"), "Inner");
    std::swap(st2.elements[0], st2.elements[1]);
    st2.elements.push_back(numeric_element<double>("extra", {1}));
    CHECK(unpack_ok(st2, "Inner") == inner(1, "x"));

    // Multi-dim: dims product must match; dims/array must be present.
    MessageElement md = pack_ok(Value(MultiDimArray{{2, 2}, NumericArray::from<double>({1, 2, 3, 4})}), "double[*]");
    MessageElement md_bad = md;
    md_bad.elements[0] = numeric_element<std::uint32_t>("dims", {3, 2});
    CHECK(unpack_error(md_bad, "double[*]").type == MessageErrorType::DataTypeError);
    md_bad.elements[0] = numeric_element<std::uint32_t>("dims", {});
    CHECK(unpack_error(md_bad, "double[*]").type == MessageErrorType::DataTypeError);
    md_bad.elements[0] = numeric_element<std::int32_t>("dims", {2, 2});
    CHECK(unpack_error(md_bad, "double[*]").type == MessageErrorType::DataTypeMismatch);
    md_bad.elements[0] = numeric_element<std::uint32_t>("dims", {0xffffffffu, 0xffffffffu, 0xffffffffu});
    CHECK(unpack_error(md_bad, "double[*]").type == MessageErrorType::DataTypeError);  // product overflow
    md_bad.elements.erase(md_bad.elements.begin());
    CHECK(unpack_error(md_bad, "double[*]").type == MessageErrorType::MessageElementNotFound);
    CHECK(unpack_error(md, "double[4,1]").type == MessageErrorType::DataTypeError);

    // Pods: item numbering, item type, missing field, count.
    MessageElement pod = pack_ok(Value(samples({1, 2})), "Sample[]");
    MessageElement pod_bad = pod;
    pod_bad.elements[1].number = 5;
    CHECK(unpack_error(pod_bad, "Sample[]").type == MessageErrorType::DataTypeError);
    pod_bad = pod;
    pod_bad.elements[0].type = DataTypes::structure_t;
    CHECK(unpack_error(pod_bad, "Sample[]").type == MessageErrorType::DataTypeMismatch);
    pod_bad = pod;
    pod_bad.elements[0].elements.pop_back();
    CHECK(unpack_error(pod_bad, "Sample[]").type == MessageErrorType::MessageElementNotFound);
    CHECK(unpack_error(pod, "Sample").type == MessageErrorType::DataTypeError);
    CHECK(unpack_error(pod, "Sample[3]").type == MessageErrorType::DataTypeError);
    pod_bad = pod;
    pod_bad.elements[0].elements[1] = numeric_element<std::int32_t>("ids", {1, 2, 3, 4});
    CHECK(unpack_error(pod_bad, "Sample[]").type == MessageErrorType::DataTypeError);

    // Namedarrays: data must be whole items of the right element type.
    MessageElement na = pack_ok(vec3s({1, 2, 3}), "Vec3");
    na.elements[0] = numeric_element<double>("array", {1, 2, 3, 4});
    CHECK(unpack_error(na, "Vec3[]").type == MessageErrorType::DataTypeError);
    na.elements[0] = numeric_element<float>("array", {1, 2, 3});
    CHECK(unpack_error(na, "Vec3").type == MessageErrorType::DataTypeMismatch);
    na.elements.clear();
    CHECK(unpack_error(na, "Vec3").type == MessageErrorType::MessageElementNotFound);
}

TEST_CASE("unpack: a varvalue with an unknown named type is an error when typed") {
    MessageElement e;
    e.type = DataTypes::structure_t;
    e.type_name = "example.test.Unknown";
    CHECK(unpack_error(e, "varvalue").type == MessageErrorType::DataTypeError);
    e.type_name = "example.test.Vec3";  // a namedarray, not a struct
    CHECK(unpack_error(e, "varvalue").type == MessageErrorType::DataTypeMismatch);
    MessageElement pod_item;
    pod_item.type = DataTypes::pod_t;
    CHECK(unpack_error(pod_item, "varvalue").type == MessageErrorType::DataTypeError);
}

TEST_CASE("unpack_value_untyped decodes self-describing values without a robdef") {
    PodArray grid = samples({1, 2});
    grid.dims = {2, 1};
    MapString ms;
    ms.entries.emplace_back("s", inner(3, "three"));
    ms.entries.emplace_back("p", Value(samples({4})));
    ms.entries.emplace_back("g", Value(grid));
    ms.entries.emplace_back("v", vec3s({1, 2, 3, 4, 5, 6}));
    ms.entries.emplace_back("m", Value(MultiDimArray{{1, 2}, NumericArray::from<std::int16_t>({1, 2})}));
    ms.entries.emplace_back("l", Value(List{{Value("x"), Value()}}));
    MessageElement e = pack_ok(Value(ms), "varvalue{string}");
    auto r = unpack_value_untyped(e);
    REQUIRE(r);
    const MapString* m = r->get_if<MapString>();
    REQUIRE(m);
    // Struct: fields as varvalues (the int32 scalar comes back as int32[] of one item).
    const Structure* s = m->find("s")->get_if<Structure>();
    REQUIRE(s);
    CHECK(s->type_name == "example.test.Inner");
    CHECK(*s->find("a") == Value::array<std::int32_t>({3}));
    CHECK(*s->find("s") == Value("three"));
    // Pod: the item's fields as sent (multi-dim fields arrive flat).
    const PodArray* p = m->find("p")->get_if<PodArray>();
    REQUIRE(p);
    CHECK(p->type_name == "example.test.Sample");
    CHECK(p->count == 1);
    CHECK(p->field_names == std::vector<std::string>{"t", "ids", "tag", "v", "vs", "mat"});
    CHECK(*p->field(0, "mat") == Value::array<double>({1, 2, 3, 4}));
    CHECK(p->field(0, "v")->get_if<NamedArray>()->type_name == "example.test.Vec3");
    CHECK(m->find("g")->get_if<PodArray>()->dims == std::vector<std::uint32_t>{2, 1});
    const NamedArray* v = m->find("v")->get_if<NamedArray>();
    REQUIRE(v);
    CHECK(v->array == NumericArray::from<double>({1, 2, 3, 4, 5, 6}));
    CHECK(*m->find("m") == Value(MultiDimArray{{1, 2}, NumericArray::from<std::int16_t>({1, 2})}));
    CHECK(*m->find("l") == Value(List{{Value("x"), Value()}}));

    // Pod items with different fields are rejected.
    MessageElement pe = pack_ok(Value(samples({1, 2})), "Sample[]");
    pe.elements[1].elements.pop_back();
    auto bad = unpack_value_untyped(pe);
    REQUIRE_FALSE(bad);
    CHECK(bad.error().type == MessageErrorType::DataTypeError);
}

TEST_CASE("unpack enforces the nesting depth limit") {
    Value deep = Value::array<double>({1});
    for (int i = 0; i < 10; ++i) deep = Value(List{{deep}});
    Limits small;
    small.max_nesting_depth = 8;
    auto p = pack_value(deep, type_of("varvalue"), "v", example_lookup(), kSvc, small);
    REQUIRE_FALSE(p);
    CHECK(p.error().type == MessageErrorType::ProtocolError);
    MessageElement e = pack_ok(deep, "varvalue");
    auto u = unpack_value(e, type_of("varvalue"), example_lookup(), kSvc, small);
    REQUIRE_FALSE(u);
    CHECK(u.error().type == MessageErrorType::ProtocolError);
    auto un = unpack_value_untyped(e, small);
    REQUIRE_FALSE(un);
    CHECK(un.error().type == MessageErrorType::ProtocolError);
    CHECK(unpack_value_untyped(e));  // default limit is deep enough
}

TEST_CASE("invalid definitions are errors, not crashes") {
    // Received definitions are parsed but not verified: packing must survive whatever they say.
    auto l = make_lookup({R"(service bad
namedarray Loop
    field Loop self
end
namedarray Mixed
    field double a
    field int32 b
end
pod HasString
    field string s
end
pod Open
    field double[*] m
end
)"});
    for (const char* t : {"Loop", "Mixed"}) {
        INFO(t);
        auto r = pack_value(Value(NamedArray{std::string("bad.") + t, NumericArray::from<double>({1}), {}}),
                            type_of(t), "v", l, "bad");
        REQUIRE_FALSE(r);
        CHECK(r.error().type == MessageErrorType::DataTypeError);
    }
    for (const char* t : {"HasString", "Open"}) {
        INFO(t);
        auto r = pack_value(Value(PodArray{std::string("bad.") + t, {}}), type_of(std::string(t) + "[]"), "v", l, "bad");
        REQUIRE_FALSE(r);
        CHECK(r.error().type == MessageErrorType::DataTypeError);
    }
}
