#include <catch2/catch.hpp>

#include "base/message/element_number.hpp"

using namespace rr;

TEST_CASE("message: element numbers read back only from canonical decimal text") {
    CHECK(parse_element_number("0") == 0);
    CHECK(parse_element_number("17") == 17);
    CHECK(parse_element_number("-1") == -1);
    CHECK(parse_element_number("2147483647") == 2147483647);
    CHECK(parse_element_number("-2147483648") == INT32_MIN);
    for (const char* s : {"", "-", "-0", "01", "+1", " 1", "1 ", "1a", "2147483648", "-2147483649", "99999999999",
                          "0x1", "value"}) {
        INFO(s);
        CHECK_FALSE(parse_element_number(s));
    }
    CHECK(ElementNumberText(0).view() == "0");
    CHECK(ElementNumberText(-129).view() == "-129");
    CHECK(ElementNumberText(INT32_MIN).view() == "-2147483648");
    for (std::int32_t v : {0, 1, -1, 9, 10, 124, 125, -128, -129, 65536, INT32_MAX, INT32_MIN})
        CHECK(parse_element_number(ElementNumberText(v).view()) == v);
}
