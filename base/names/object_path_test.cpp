// Object paths (object_path.hpp): parsing in both index forms, the normalized text, splitting a member
// off, and every parse error once. The walk through the objrefs' types is core/names/object_path_walk_test.cpp.
#include <catch2/catch.hpp>

#include "base/names/object_path.hpp"

using namespace rr;

namespace {

std::string parse_error(std::string_view path, ObjectPathIndexes indexes = ObjectPathIndexes::plain_or_encoded) {
    auto r = parse_object_path(path, indexes);
    REQUIRE_FALSE(r);
    CHECK(r.error().type == MessageErrorType::InvalidArgument);
    return r.error().message;
}

}  // namespace

TEST_CASE("object path: segments, indexes decoded, the service-path text") {
    auto p = parse_object_path("arms[left.arm].tool");
    REQUIRE(p);
    REQUIRE(p->segments.size() == 2);
    CHECK(p->segments[0].name == "arms");
    CHECK(p->segments[0].has_index);
    CHECK(p->segments[0].index == "left.arm");
    CHECK(p->segments[0].encoded_index == "left%2earm");
    CHECK_FALSE(p->segments[1].has_index);
    CHECK(p->text() == "arms[left%2earm].tool");
    // An index already encoded is kept as given (its text is the service's object key), and decoded.
    p = parse_object_path("child_by_int[%2d1].a_b[x_y]");
    REQUIRE(p);
    CHECK(p->segments[0].index == "-1");
    CHECK(p->segments[1].encoded_index == "x_y");
    CHECK(p->text() == "child_by_int[%2d1].a_b[x_y]");
    CHECK(*normalize_object_path("child_by_int[-1]") == "child_by_int[%2d1]");
    CHECK(*normalize_object_path("c[with space]") == "c[with%20space]");
    // From the wire, indexes must be encoded already.
    auto wire = parse_object_path("arms[left%2earm].tool", ObjectPathIndexes::encoded);
    REQUIRE(wire);
    CHECK(wire->segments[0].index == "left.arm");
}

TEST_CASE("object path: every parse error once") {
    CHECK(parse_error("") == "object path \"\" is empty");
    CHECK(parse_error("a..b") == "object path \"a..b\": expected a member name at offset 2");
    CHECK(parse_error("arms[x") == "object path \"arms[x\": '[' without ']'");
    CHECK(parse_error("arms[]") == "object path \"arms[]\": empty index");
    CHECK(parse_error("arms[a b]", ObjectPathIndexes::encoded) ==
          "object path \"arms[a b]\": index \"a b\" is not in service-path encoding (letters, digits, '_', %hh)");
    CHECK(parse_error("arms[1]x") == "object path \"arms[1]x\": unexpected 'x' at offset 7");
    CHECK(parse_error("main.") == "object path \"main.\" ends with '.'");
}

TEST_CASE("object path: a member splits off at its last dot outside brackets") {
    CHECK(split_member_path("packets").object.empty());
    CHECK(split_member_path("packets").member == "packets");
    auto p = split_member_path("arms[left.arm].tool.state");
    CHECK(p.object == "arms[left.arm].tool");
    CHECK(p.member == "state");
    p = split_member_path("cams[a.b]");
    CHECK(p.object.empty());
    CHECK(p.member == "cams[a.b]");
}
