#include <catch2/catch.hpp>

#include "core/value/var_type.hpp"

using namespace rr;
using robdef::ArrayKind;
using robdef::ContainerKind;

TEST_CASE("parse_type_string reads every array and container form") {
    auto t = parse_type_string("double");
    REQUIRE(t);
    CHECK(t->base == DataTypes::double_t);
    CHECK(t->array == ArrayKind::none);

    t = parse_type_string("uint8[]");
    REQUIRE(t);
    CHECK(t->array == ArrayKind::array);
    CHECK(t->array_var_length);
    CHECK(t->array_length.empty());

    t = parse_type_string("int32[3]");
    REQUIRE(t);
    CHECK_FALSE(t->array_var_length);
    CHECK(t->array_length == std::vector<std::int32_t>{3});

    t = parse_type_string("int32[3-]");
    REQUIRE(t);
    CHECK(t->array_var_length);
    CHECK(t->array_length == std::vector<std::int32_t>{3});

    t = parse_type_string("single[*]");
    REQUIRE(t);
    CHECK(t->array == ArrayKind::multidimarray);
    CHECK(t->array_var_length);

    t = parse_type_string("single[2,3,4]");
    REQUIRE(t);
    CHECK(t->array == ArrayKind::multidimarray);
    CHECK_FALSE(t->array_var_length);
    CHECK(t->array_length == std::vector<std::int32_t>{2, 3, 4});

    t = parse_type_string("single[5,]");
    REQUIRE(t);
    CHECK(t->array == ArrayKind::multidimarray);
    CHECK(t->array_length == std::vector<std::int32_t>{5});

    t = parse_type_string("  example.test.Pose[2]{int32}  value ");
    REQUIRE(t);
    CHECK(t->base == DataTypes::namedtype_t);
    CHECK(t->type_name == "example.test.Pose");
    CHECK(t->container == ContainerKind::map_int32);
    CHECK(t->name == "value");
    CHECK(t->to_string() == "example.test.Pose[2]{int32}");

    t = parse_type_string("varvalue{string}");
    REQUIRE(t);
    CHECK(t->base == DataTypes::varvalue_t);
    CHECK(t->container == ContainerKind::map_string);

    t = parse_type_string("string{list}");
    REQUIRE(t);
    CHECK(t->container == ContainerKind::list);

    t = parse_type_string("double[0]");  // [0] behaves as []
    REQUIRE(t);
    CHECK(t->array_var_length);
    CHECK(t->array_length.empty());
}

TEST_CASE("parse_type_string rejects malformed and non-value types") {
    for (const char* bad : {"", "[]", "double[", "double[-3]", "double[*-]", "double[2,,3]", "double{generator}",
                            "double{uint32}", "double{list}{list}", "double{list}[]", "object", "varobject",
                            "structure", "void[]", "a..b", "a.", "double[99999999999]", "double x y", "1abc"}) {
        INFO(bad);
        auto r = parse_type_string(bad);
        REQUIRE_FALSE(r);
        CHECK(r.error().type == MessageErrorType::DataTypeError);
    }
}
