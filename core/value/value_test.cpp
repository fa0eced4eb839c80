#include <catch2/catch.hpp>

#include <limits>

#include "core/value/value.hpp"

using namespace rr;

TEST_CASE("Value holds every kind and reports it") {
    CHECK(Value().is_null());
    CHECK(Value::scalar<double>(1.5).kind() == ValueKind::numeric);
    CHECK(Value("abc").kind() == ValueKind::string);
    CHECK(Value(MultiDimArray{{2, 2}, NumericArray::from<double>({1, 2, 3, 4})}).kind() == ValueKind::multidim);
    CHECK(Value(Structure{"svc.S", {}}).kind() == ValueKind::structure);
    CHECK(Value(PodArray{"svc.P", {"a"}}).kind() == ValueKind::pod);
    CHECK(Value(NamedArray{"svc.N", NumericArray::from<float>({1, 2}), {}}).kind() == ValueKind::namedarray);
    CHECK(Value(MapInt32{}).kind() == ValueKind::map_int32);
    CHECK(Value(MapString{}).kind() == ValueKind::map_string);
    CHECK(Value(List{}).kind() == ValueKind::list);
    CHECK(Value(Enum{"svc.E", 2}).kind() == ValueKind::enumeration);
}

TEST_CASE("Value::as converts scalars only when lossless in range") {
    CHECK(Value::scalar<double>(1.5).as<double>().value() == 1.5);
    CHECK(Value::scalar<std::int8_t>(-5).as<std::int64_t>().value() == -5);
    CHECK(Value::scalar<std::uint64_t>(7).as<std::int32_t>().value() == 7);
    CHECK(Value::scalar<std::int32_t>(7).as<double>().value() == 7.0);
    CHECK(Value::scalar<double>(2.0).as<cdouble>().value() == cdouble(2.0, 0.0));
    CHECK(Value(Enum{"svc.E", 3}).as<std::int32_t>().value() == 3);
    CHECK(Value("x").as<std::string>().value() == "x");

    auto big = Value::scalar<std::uint64_t>(std::numeric_limits<std::uint64_t>::max()).as<std::int64_t>();
    REQUIRE_FALSE(big);
    CHECK(big.error().type == MessageErrorType::OutOfRange);
    auto neg = Value::scalar<std::int32_t>(-1).as<std::uint8_t>();
    REQUIRE_FALSE(neg);
    CHECK(neg.error().type == MessageErrorType::OutOfRange);
    auto real_to_int = Value::scalar<double>(1.0).as<std::int32_t>();
    REQUIRE_FALSE(real_to_int);
    CHECK(real_to_int.error().type == MessageErrorType::DataTypeMismatch);
    auto int_to_bool = Value::scalar<std::int32_t>(1).as<bool>();
    REQUIRE_FALSE(int_to_bool);
    CHECK(int_to_bool.error().type == MessageErrorType::DataTypeMismatch);
    auto arr = Value::array<double>({1, 2}).as<double>();
    REQUIRE_FALSE(arr);
    CHECK(arr.error().type == MessageErrorType::DataTypeError);
    auto str = Value("1").as<double>();
    REQUIRE_FALSE(str);
    CHECK(str.error().type == MessageErrorType::DataTypeMismatch);
}

TEST_CASE("Structure fields keep order, can be replaced and looked up") {
    Structure s{"svc.S", {}};
    s.set("b", Value::scalar<std::int32_t>(1)).set("a", Value("x")).set("b", Value::scalar<std::int32_t>(2));
    REQUIRE(s.fields.size() == 2);
    CHECK(s.fields[0].name == "b");
    Value v(std::move(s));
    REQUIRE(v.field("b"));
    CHECK(v.field("b")->as<std::int32_t>().value() == 2);
    CHECK(v.field("missing") == nullptr);
    Value copy = v;
    copy.field("a")->get_if<std::string>()->assign("y");
    CHECK(v.field("a")->as<std::string>().value() == "x");
    CHECK_FALSE(copy == v);
}

TEST_CASE("PodArray stores items flat and checks item width") {
    PodArray p{"svc.P", {"x", "y"}};
    REQUIRE(p.push_back({Value::scalar<double>(1), Value::scalar<double>(2)}));
    REQUIRE(p.push_back({Value::scalar<double>(3), Value::scalar<double>(4)}));
    auto bad = p.push_back({Value::scalar<double>(5)});
    REQUIRE_FALSE(bad);
    CHECK(bad.error().type == MessageErrorType::DataTypeError);
    CHECK(p.size() == 2);
    CHECK(p.field(1, "y")->as<double>().value() == 4);
    CHECK(p.field(2, "y") == nullptr);
    CHECK(p.field(0, "z") == nullptr);
    Value v(p);
    CHECK(v.field("x")->as<double>().value() == 1);
}

TEST_CASE("Containers look up by key and list by index") {
    MapInt32 m;
    m.entries.emplace_back(5, Value("five"));
    MapString ms;
    ms.entries.emplace_back("k", Value::scalar<bool>(true));
    List l;
    l.items.push_back(Value::scalar<std::int32_t>(1));
    CHECK(m.find(5)->as<std::string>().value() == "five");
    CHECK(m.find(6) == nullptr);
    CHECK(ms.find("k")->as<bool>().value());
    Value lv(l);
    CHECK(lv.at(0)->as<std::int32_t>().value() == 1);
    CHECK(lv.at(1) == nullptr);
}
