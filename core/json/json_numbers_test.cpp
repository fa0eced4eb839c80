#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

#include "core/json/json_numbers.hpp"
#include "core/json/utf8.hpp"

using namespace rr;
using nlohmann::json;
namespace jnum = rr::json_numbers;

TEST_CASE("json numbers: 64-bit integers are numbers up to 2^53, decimal strings beyond") {
    CHECK(jnum::to_json<std::int64_t>(9007199254740992) == json(9007199254740992));
    CHECK(jnum::to_json<std::int64_t>(-9007199254740992) == json(-9007199254740992));
    CHECK(jnum::to_json<std::int64_t>(9007199254740993) == json("9007199254740993"));
    CHECK(jnum::to_json<std::int64_t>(std::numeric_limits<std::int64_t>::min()) == json("-9223372036854775808"));
    CHECK(jnum::to_json<std::uint64_t>(std::numeric_limits<std::uint64_t>::max()) == json("18446744073709551615"));
    CHECK(jnum::to_json<std::uint64_t>(9007199254740992u) == json(9007199254740992u));
    CHECK(jnum::to_json<std::int32_t>(std::numeric_limits<std::int32_t>::min()) == json(-2147483648));

    CHECK(jnum::from_json<std::int64_t>(json("-9223372036854775808")).value() == std::numeric_limits<std::int64_t>::min());
    CHECK(jnum::from_json<std::uint64_t>(json("18446744073709551615")).value() == std::numeric_limits<std::uint64_t>::max());
    CHECK(jnum::from_json<std::uint64_t>(json::parse("18446744073709551615")).value() ==
          std::numeric_limits<std::uint64_t>::max());
    CHECK(jnum::from_json<std::int64_t>(json::parse("-9223372036854775808")).value() ==
          std::numeric_limits<std::int64_t>::min());
    CHECK(jnum::from_json<std::int8_t>(json("-128")).value() == -128);
    CHECK(jnum::from_json<std::uint16_t>(json(3.0)).value() == 3);  // integral floats are fine
}

TEST_CASE("json numbers: integer range and kind errors") {
    CHECK(jnum::from_json<std::int8_t>(json(128)).error().type == MessageErrorType::OutOfRange);
    CHECK(jnum::from_json<std::int8_t>(json(-129)).error().type == MessageErrorType::OutOfRange);
    CHECK(jnum::from_json<std::uint8_t>(json(-1)).error().type == MessageErrorType::OutOfRange);
    CHECK(jnum::from_json<std::uint32_t>(json(4294967296)).error().type == MessageErrorType::OutOfRange);
    CHECK(jnum::from_json<std::int64_t>(json("9223372036854775808")).error().type == MessageErrorType::OutOfRange);
    CHECK(jnum::from_json<std::uint64_t>(json("-1")).error().type == MessageErrorType::OutOfRange);
    CHECK(jnum::from_json<std::int32_t>(json(1.5)).error().type == MessageErrorType::OutOfRange);
    CHECK(jnum::from_json<std::int64_t>(json(1e300)).error().type == MessageErrorType::OutOfRange);
    CHECK(jnum::from_json<std::int32_t>(json("12abc")).error().type == MessageErrorType::DataTypeMismatch);
    CHECK(jnum::from_json<std::int32_t>(json("+1")).error().type == MessageErrorType::DataTypeMismatch);
    CHECK(jnum::from_json<std::int32_t>(json(" 1")).error().type == MessageErrorType::DataTypeMismatch);
    CHECK(jnum::from_json<std::int32_t>(json(true)).error().type == MessageErrorType::DataTypeMismatch);
    CHECK(jnum::from_json<std::int32_t>(json(nullptr)).error().type == MessageErrorType::DataTypeMismatch);
    CHECK(jnum::from_json<bool>(json(1)).error().type == MessageErrorType::DataTypeMismatch);
}

TEST_CASE("json numbers: reals round-trip exactly, including NaN, infinities and -0") {
    for (double d : {0.1, -0.0, 1e-310, 1.7976931348623157e308, 3.141592653589793, -2.5e-7}) {
        json j = jnum::to_json(d);
        json back = json::parse(j.dump());
        double r = jnum::from_json<double>(back).value();
        CHECK(std::bit_cast<std::uint64_t>(r) == std::bit_cast<std::uint64_t>(d));
    }
    CHECK(jnum::to_json(std::numeric_limits<double>::quiet_NaN()) == json("NaN"));
    CHECK(jnum::to_json(std::numeric_limits<double>::infinity()) == json("Infinity"));
    CHECK(jnum::to_json(-std::numeric_limits<double>::infinity()) == json("-Infinity"));
    CHECK(std::isnan(jnum::from_json<double>(json("NaN")).value()));
    CHECK(jnum::from_json<double>(json("-Infinity")).value() == -std::numeric_limits<double>::infinity());
    CHECK(jnum::from_json<double>(json(3)).value() == 3.0);
    for (float f : {0.1f, -1e-40f, 3.4028235e38f}) {
        float r = jnum::from_json<float>(json::parse(jnum::to_json(f).dump())).value();
        CHECK(std::bit_cast<std::uint32_t>(r) == std::bit_cast<std::uint32_t>(f));
    }
    CHECK(jnum::from_json<float>(json(1e39)).error().type == MessageErrorType::OutOfRange);
    CHECK(jnum::from_json<double>(json("nan")).error().type == MessageErrorType::DataTypeMismatch);
    CHECK(jnum::from_json<double>(json("1.5")).error().type == MessageErrorType::DataTypeMismatch);
}

TEST_CASE("json numbers: complex is {re, im}") {
    CHECK(jnum::to_json(cdouble(1.5, -2)) == json::parse(R"({"re":1.5,"im":-2.0})"));
    CHECK(jnum::from_json<csingle>(json::parse(R"({"im":"Infinity","re":0.5})")).value() ==
          csingle(0.5f, std::numeric_limits<float>::infinity()));
    CHECK(jnum::from_json<cdouble>(json::parse(R"({"re":1})")).error().type == MessageErrorType::DataTypeMismatch);
    CHECK(jnum::from_json<cdouble>(json::parse(R"({"re":1,"im":2,"x":3})")).error().type ==
          MessageErrorType::DataTypeMismatch);
    CHECK(jnum::from_json<cdouble>(json::parse("[1,2]")).error().type == MessageErrorType::DataTypeMismatch);
}

TEST_CASE("json numbers: arrays") {
    auto a = jnum::array_from_json(json::parse("[1, 2, 255]"), DataTypes::uint8_t);
    REQUIRE(a);
    CHECK(*a == NumericArray::from<std::uint8_t>({1, 2, 255}));
    CHECK(jnum::array_to_json(*a) == json::parse("[1,2,255]"));
    std::size_t bad = 99;
    auto b = jnum::array_from_json(json::parse("[1, 256]"), DataTypes::uint8_t, &bad);
    REQUIRE_FALSE(b);
    CHECK(b.error().type == MessageErrorType::OutOfRange);
    CHECK(bad == 1);
    CHECK(jnum::array_from_json(json(1), DataTypes::double_t).error().type == MessageErrorType::DataTypeMismatch);
    CHECK(jnum::array_from_json(json::array(), DataTypes::bool_t).value().empty());
}

TEST_CASE("UTF-8 validation") {
    CHECK(is_valid_utf8(""));
    CHECK(is_valid_utf8("plain ascii"));
    CHECK(is_valid_utf8("h\xc3\xa9llo \xe2\x82\xac \xf0\x9f\x98\x80"));
    CHECK_FALSE(is_valid_utf8("\xc3"));              // truncated
    CHECK_FALSE(is_valid_utf8("\xc0\xaf"));          // overlong
    CHECK_FALSE(is_valid_utf8("\xe0\x80\xaf"));      // overlong 3-byte
    CHECK_FALSE(is_valid_utf8("\xed\xa0\x80"));      // surrogate
    CHECK_FALSE(is_valid_utf8("\xf4\x90\x80\x80"));  // above U+10FFFF
    CHECK_FALSE(is_valid_utf8("\x80"));              // stray continuation
    CHECK_FALSE(is_valid_utf8("\xff"));
}
