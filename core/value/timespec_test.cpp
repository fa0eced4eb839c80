#include <catch2/catch.hpp>

#include "core/value/timespec.hpp"

using namespace rr;

TEST_CASE("TimeSpec packs as RobotRaconteur.TimeSpec {seconds:int64, nanoseconds:int32}") {
    TimeSpec t{1700000000, 123456789};
    MessageElement e = pack_timespec(t, "ts");
    CHECK(e.name == "ts");
    CHECK(e.type == DataTypes::structure_t);
    CHECK(e.type_name == "RobotRaconteur.TimeSpec");
    REQUIRE(e.elements.size() == 2);
    CHECK(e.elements[0].name == "seconds");
    CHECK(e.elements[0].type == DataTypes::int64_t);
    CHECK(e.elements[0].data_count() == 1);
    CHECK(e.elements[1].name == "nanoseconds");
    CHECK(e.elements[1].type == DataTypes::int32_t);
    auto back = unpack_timespec(e);
    REQUIRE(back);
    CHECK(*back == t);
    auto v = timespec_from_value(timespec_to_value(t));
    REQUIRE(v);
    CHECK(*v == t);
}

TEST_CASE("TimeSpec errors") {
    CHECK(unpack_timespec(MessageElement{}).error().type == MessageErrorType::NullValue);
    MessageElement e = pack_timespec({1, 2}, "ts");
    MessageElement wrong = e;
    wrong.type_name = "RobotRaconteur.Other";
    CHECK(unpack_timespec(wrong).error().type == MessageErrorType::DataTypeMismatch);
    wrong = e;
    wrong.elements.pop_back();
    CHECK(unpack_timespec(wrong).error().type == MessageErrorType::MessageElementNotFound);
    wrong = e;
    wrong.elements[0].type = DataTypes::uint64_t;
    CHECK(unpack_timespec(wrong).error().type == MessageErrorType::DataTypeMismatch);
    MessageElement bad_ns = pack_timespec({1, 1'000'000'000}, "ts");
    CHECK(unpack_timespec(bad_ns).error().type == MessageErrorType::DataTypeError);
    CHECK(timespec_from_value(Value("x")).error().type == MessageErrorType::DataTypeMismatch);
    CHECK(timespec_from_value(Value()).error().type == MessageErrorType::NullValue);
}
