// Canonical text form (robdef.md §12).
#include <catch2/catch.hpp>

#include "robdef/canonical_text.hpp"
#include "robdef/parser.hpp"

using namespace rr::robdef;

namespace {

std::string canon(std::string_view text) {
    auto r = parse_service_definition(text, "t.robdef");
    REQUIRE(r);
    return to_string(r->definition);
}

}  // namespace

TEST_CASE("canonical text: sections, regrouping, using abbreviation, modifiers, enums") {
    const std::string text =
        "# header comment\n"
        "service a.b\n"
        "\n"
        "stdver 0.10\n"
        "import c.d\n"
        "using c.d.T\n"
        "using c.d.Other as O2\n"
        "exception Broken\n"
        "constant uint32 MASK 0xFF\n"
        "enum E\n"
        "    ## doc\n"
        "    a = 0x10, b,\n"
        "    c = -0x5,\n"
        "    d = -7\n"
        "end\n"
        "object Obj\n"
        "\timplements O2\n"
        "\tconstant double X -1e-3\n"
        "\tproperty   T   t   [readonly, nolock]\n"
        "\tfunction void f (c.d.T a,int32[0] b)\n"
        "\tevent e()\n"
        "\tobjref Obj[] kids\n"
        "end\n"
        "struct S\n"
        "    field double[3,] m\n"
        "end\n"
        "namedarray N\n"
        "    field double x\n"
        "end\n"
        "pod P\n"
        "    field uint8[4-] b\n"
        "end\n";
    const std::string expected =
        "service a.b\n"
        "\n"
        "stdver 0.10\n"
        "\n"
        "import c.d\n"
        "\n"
        "using c.d.T\n"
        "using c.d.Other as O2\n"
        "\n"
        "constant uint32 MASK 0xFF\n"
        "\n"
        "enum E\n"
        "    a = 0x10,\n"
        "    b,\n"
        "    c = -0x5,\n"
        "    d = -7\n"
        "end\n"
        "\n"
        "\n"
        "exception Broken\n"
        "\n"
        "struct S\n"
        "    field double[3,] m\n"
        "end\n"
        "\n"
        "pod P\n"
        "    field uint8[4-] b\n"
        "end\n"
        "\n"
        "namedarray N\n"
        "    field double x\n"
        "end\n"
        "\n"
        "object Obj\n"
        "    implements O2\n"
        "    constant double X -1e-3\n"
        "    property T t [readonly,nolock]\n"
        "    function void f(T a, int32[] b)\n"
        "    event e()\n"
        "    objref Obj[] kids\n"
        "end\n"
        "\n";
    CHECK(canon(text) == expected);
    CHECK(canon(expected) == expected);
}

TEST_CASE("canonical text: legacy option version stays an option, old stdver becomes option version") {
    const std::string legacy =
        "service experimental.old\n"
        "option version 0.8\n"
        "object O\n"
        "    option constant int16 C 1\n"
        "    pipe double p\n"
        "end object\n";
    const std::string expected =
        "service experimental.old\n"
        "\n"
        "option version 0.8\n"
        "\n"
        "object O\n"
        "    option constant int16 C 1\n"
        "    pipe double p\n"
        "end\n"
        "\n";
    CHECK(canon(legacy) == expected);

    ServiceDefinition d;
    d.name = "x.y";
    d.stdver = Version{0, 8, 0, 0};
    CHECK(to_string(d) == "service x.y\n\noption version 0.8\n\n");
    d.stdver = Version{0, 9, 2, 0};
    CHECK(to_string(d) == "service x.y\n\nstdver 0.9.2\n\n");
}

TEST_CASE("canonical text: empty enum and member_to_string") {
    CHECK(canon("service a.b\nstdver 0.10\nenum E\nend\n") == "service a.b\n\nstdver 0.10\n\nenum E\n\nend\n\n\n");
    auto r = parse_service_definition("service a.b\nstruct S\n    field double{list} x\nend\n", "t");
    REQUIRE(r);
    const auto& m = r->definition.structures.at(0).members.at(0);
    CHECK(member_to_string(m, r->definition, false) == "field double{list} x");
    CHECK(member_to_string(m, r->definition, true) == "property double{list} x");
}

TEST_CASE("canonical text: an option ending in a backslash reads back the same") {
    // `x\\` continued onto a blank line leaves the option text `x\` (robdef.md §1.2).
    const std::string text = "service a.b\noption x\\\\\n\nstruct S\n    option y\\\\\n\n    field int32 f\nend\n";
    auto r = parse_service_definition(text, "t.robdef");
    REQUIRE(r);
    REQUIRE(r->definition.options == std::vector<std::string>{"x\\"});
    REQUIRE(r->definition.structures.at(0).options == std::vector<std::string>{"y\\"});
    const std::string once = to_string(r->definition);
    auto again = parse_service_definition(once, "canonical.robdef");
    REQUIRE(again);
    CHECK(again->definition.options == r->definition.options);
    CHECK(again->definition.structures.at(0).options == r->definition.structures.at(0).options);
    CHECK(to_string(again->definition) == once);
}

TEST_CASE("canonical text: options of a stdver >= 0.9.2 definition go above the stdver line") {
    // Legal only there (robdef.md §2.2); the official ToString writes them below, where its own parser
    // rejects them. Below 0.9.2, and with `option version`, the official order is kept.
    const std::string once = canon("service a.b\noption foo\noption bar\nstdver 0.10\nimport c.d\nusing c.d.T\n");
    CHECK(once == "service a.b\n\noption foo\noption bar\n\nstdver 0.10\n\nimport c.d\n\nusing c.d.T\n\n");
    CHECK(canon(once) == once);
    CHECK(canon("service a.b\nstdver 0.9\nimport c.d\noption foo\n") ==
          "service a.b\n\nstdver 0.9\n\nimport c.d\n\noption foo\n\n");
    CHECK(canon("service a.b\noption version 0.8\noption foo\n") ==
          "service a.b\n\noption version 0.8\noption foo\n\n");
}
