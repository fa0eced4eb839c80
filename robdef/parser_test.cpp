// Parser tests: invalid definitions (expected kind, official message text, physical line) and
// tricky valid forms (robdef.md §1–§9).
#include <catch2/catch.hpp>

// GCC 12 at -O2 warns falsely on `std::string + "literal"` (bug 105651); the table below uses it a lot.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wrestrict"
#endif

#include "robdef/parser.hpp"
#include "robdef/test_support.hpp"

using namespace rr::robdef;
using rr::robdef::test::dump;

namespace {

struct ParseCase {
    const char* what;
    std::string text;
    DiagnosticKind kind;
    std::string message;
    int line;
};

// The parser's message for a byte-order mark in text, up to the column.
const std::string kBomInText =
    "Service definition must contain only ASCII characters (a UTF-8 byte-order mark, bytes EF BB BF, at column ";

ServiceDefinition parse_ok(std::string_view text) {
    auto r = parse_service_definition_report(text, "t.robdef");
    INFO(dump(r.diagnostics));
    REQUIRE(r.ok());
    return std::move(*r.definition);
}

}  // namespace

TEST_CASE("invalid definitions fail to parse with the official message at the right line") {
    using K = DiagnosticKind;
    const std::string h = "service a.b\n";           // line 1
    const std::string h10 = "service a.b\nstdver 0.10\n";  // lines 1-2
    const std::vector<ParseCase> cases{
        // --- lexical (robdef.md §1)
        {"NUL byte", h + std::string("struct S\0\nend\n", 14), K::syntax,
         "Service definition must not contain null characters", 2},
        {"UTF-8 in a comment", h + "# caf\xC3\xA9\n", K::syntax,
         "Service definition must contain only ASCII characters", 2},
        {"lone CR is not a line break", "service a.b\rstruct S\nend\n", K::syntax,
         "Service definition must contain only ASCII characters", 1},
        {"continuation on the last line", h + "struct S \\", K::syntax,
         "Service definition line continuation must not be on last line", 2},
        {"error after a continuation reports the physical line",
         h + "object O\n    wire int32 \\\n        w\n    property double x # c\nend\n", K::syntax,
         "Could not parse property", 5},
        // --- statements and ordering (robdef.md §2)
        {"first statement is not service", "stdver 0.10\nservice a.b\n", K::ordering,
         "service name must be first entry in service definition", 1},
        {"second service statement", h + "service c.d\n", K::ordering,
         "service name must be first entry in service definition", 2},
        {"unknown keyword", h + "structure S\nend\n", K::syntax, "Parse error", 2},
        {"keyword is case-sensitive", h + "OBJECT O\nend\n", K::syntax, "Parse error", 2},
        {"bad service name", "service a..b\n", K::syntax, "Format error for service definition \"service a..b\"", 1},
        {"stdver after import", h + "import c.d\nstdver 0.10\n", K::ordering, "stdver must be first after service name",
         3},
        {"stdver bad format", h + "stdver 0.10a\n", K::version, "Format error for version definition \"0.10a\"", 2},
        {"stdver with five parts", h + "stdver 0.9.2.1.1\n", K::version,
         "Format error for version definition \"0.9.2.1.1\"", 2},
        {"stdver below 0.9", h + "stdver 0.8\n", K::version,
         "Service definition standard version 0.9 or greater required for \"stdver\" keyword", 2},
        {"option with stdver 0.10", h10 + "option foo\n", K::version,
         "option keyword is not support in stdver 0.9.2 or greater", 3},
        {"option between two stdver lines", "service a.b\nstdver 0.10\noption foo\nstdver 0.9\n", K::version,
         "option keyword is not support in stdver 0.9.2 or greater", 3},
        {"option inside an object with stdver 0.9.2", "service a.b\nstdver 0.9.2\nobject O\n    option x\nend\n",
         K::version, "option keyword is not support in stdver 0.9.2 or greater", 4},
        {"import after struct", h + "struct S\nend\nimport c.d\n", K::ordering, "import must be before all but options",
         4},
        {"import format", h + "import c-d\n", K::syntax, "Format error for import definition \"import c-d\"", 2},
        {"using after constant", h10 + "constant int32 C 1\nusing c.d.E\n", K::ordering,
         "using must be after imports and before all others except options", 4},
        {"using with two blanks after as", h10 + "import c.d\nusing c.d.E as  F\n", K::syntax,
         "Format error for using  definition", 4},
        {"using of an unqualified name", h10 + "using E\n", K::syntax, "Format error for using  definition", 3},
        {"exception after struct", h + "struct S\nend\nexception E\n", K::ordering,
         "exception must be before struct and object", 4},
        {"constant after object", h10 + "object O\nend\nconstant int32 C 1\n", K::ordering,
         "constant must be before struct and object", 5},
        {"enum after pod", h10 + "pod P\n    field double x\nend\nenum E\n    a = 1\nend\n", K::ordering,
         "enum must be before struct and object", 6},
        {"option version twice with stdver", h + "option version 0.9\nstdver 0.9\n", K::version,
         "Robot Raconteur version already specified", 2},
        {"option version not numeric", h + "option version abc\n", K::version,
         "Invalid Robot Raconteur version specified", 2},
        {"option version with one part", h + "option version 1\n", K::version,
         "Format error for version definition \"1\"", 2},
        // --- blocks (robdef.md §2.3)
        {"block name ending in underscore", h + "struct S_\nend\n", K::syntax, "Parse error", 2},
        {"block end not found", h + "object O\n    property double x\n", K::block, "Block end not found", 2},
        {"end with a trailing comment is not an end", h + "struct S\n    field double x\nend # x\n", K::block,
         "Block end not found", 2},
        {"end struct with stdver 0.10", h10 + "struct S\n    field double x\nend struct\n", K::block,
         "end keyword must be only keyword on line in stdver 0.9.2 and greater", 5},
        {"end kind mismatch", h + "struct S\n    field double x\nend object\n", K::block,
         "Block end does not match start", 4},
        {"nested block", h + "object O\nstruct S\nend\n", K::syntax, "Parse error", 3},
        {"property in a struct", h + "struct S\n    property double x\nend\n", K::syntax,
         "Structures must only contain fields, constants, and options", 3},
        {"implements in a struct", h + "struct S\n    implements O\nend\n", K::syntax,
         "Structures must only contain fields, constants, and options", 3},
        {"field in an object", h + "object O\n    field double x\nend\n", K::syntax,
         "Objects cannot contain fields, use properties instead", 3},
        {"implements after a member", h + "object O\n    property double x\n    implements P\nend\n", K::ordering,
         "Structure implements must come before members", 4},
        {"constant after a field", h10 + "struct S\n    field double x\n    constant int32 C 1\nend\n", K::ordering,
         "Structure constants must come before members", 5},
        // --- members (robdef.md §4, §5.1)
        {"property without type", h + "object O\n    property x\nend\n", K::syntax, "Format error for property", 3},
        {"field without name (says property)", h + "struct S\n    field double\nend\n", K::syntax,
         "Format error for property", 3},
        {"property with parentheses", h + "object O\n    property double x()\nend\n", K::syntax,
         "Format error for property", 3},
        {"wire with parentheses", h + "object O\n    wire double w()\nend\n", K::syntax, "Format error for wire", 3},
        {"function without return type", h + "object O\n    function f()\nend\n", K::syntax,
         "Format error for function definition \"function f()\"", 3},
        {"callback without parentheses", h + "object O\n    callback void c\nend\n", K::syntax,
         "Format error for callback definition \"callback void c\"", 3},
        {"event with a type", h + "object O\n    event void e()\nend\n", K::syntax,
         "Format error for event definition \"event void e()\"", 3},
        {"blanks inside a type", h + "object O\n    property double[ 3 ] x\nend\n", K::syntax,
         "Could not parse property", 3},
        {"modifier without a blank before [", h + "object O\n    property double x[readonly]\nend\n", K::syntax,
         "Could not parse property", 3},
        {"blanks just inside the modifier brackets", h + "object O\n    property double x [readonly ]\nend\n",
         K::syntax, "Could not parse property", 3},
        {"empty modifier list", h + "object O\n    property double x []\nend\n", K::syntax,
         "Could not parse property", 3},
        {"string modifier argument", h + "object O\n    property double x [foo(\"a\")]\nend\n", K::syntax,
         "Could not parse property", 3},
        {"trailing comma in parameters", h + "object O\n    function void f(double a,)\nend\n", K::syntax,
         "Could not parse function", 3},
        {"parameter without a name", h + "object O\n    function void f(double)\nend\n", K::syntax,
         "Could not parse function", 3},
        {"extra closing parenthesis", h + "object O\n    function void f(double a))\nend\n", K::syntax,
         "Could not parse function", 3},
        // --- types (robdef.md §6.1)
        {"nested containers", h + "object O\n    property double{list}{list} x\nend\n", K::syntax,
         "Could not parse type \"double{list}{list}\"", 3},
        {"invalid container", h + "object O\n    property double{uint32} x\nend\n", K::syntax,
         "Could not parse type \"double{uint32}\": invalid container type", 3},
        {"container before array", h + "object O\n    property double{list}[] x\nend\n", K::syntax,
         "Could not parse type \"double{list}[]\"", 3},
        {"negative array length", h + "object O\n    property double[-3] x\nend\n", K::syntax,
         "Could not parse type \"double[-3]\"", 3},
        {"array length above int32", h + "object O\n    property double[2147483648] x\nend\n", K::syntax,
         "Could not parse type \"double[2147483648]\"", 3},
        {"empty multidim dimension", h + "object O\n    property double[2,,3] x\nend\n", K::syntax,
         "Could not parse type \"double[2,,3]\"", 3},
        {"objref of a primitive", h + "object O\n    objref double o\nend\n", K::syntax,
         "Invalid objref definition \"objref double o\"", 3},
        {"objref fixed array", h + "object O\n    objref P[3] o\nend\n", K::syntax,
         "Invalid objref definition \"objref P[3] o\"", 3},
        {"objref list", h + "object O\n    objref P{list} o\nend\n", K::syntax,
         "Invalid objref definition \"objref P{list} o\"", 3},
        {"objref fixed array of length 0", h + "object O\n    objref P[0] o\nend\n", K::syntax,
         "Invalid objref definition \"objref P[0] o\"", 3},
        {"objref bounded array and map", h + "object O\n    objref P[2-]{int32} o\nend\n", K::syntax,
         "Invalid objref definition \"objref P[2-]{int32} o\"", 3},
        // --- enums (robdef.md §3.2)
        {"enum first value implicit", h10 + "enum E\n    a,\n    b\nend\n", K::enumeration,
         "Enum first value must be specified", 4},
        {"enum missing comma", h10 + "enum E\n    a = 1\n    b\nend\n", K::enumeration, "Enum parse error", 5},
        {"enum duplicate value", h10 + "enum E\n    a = 1,\n    b = 1\nend\n", K::enumeration,
         "Enum names or values not unique", 5},
        {"enum duplicate implicit value", h10 + "enum E\n    a = 1,\n    b = 0,\n    c\nend\n", K::enumeration,
         "Enum names or values not unique", 6},
        {"enum duplicate name", h10 + "enum E\n    a = 1, a = 2\nend\n", K::enumeration,
         "Enum names or values not unique", 4},
        {"enum value overflow", h10 + "enum E\n    a = 2147483648\nend\n", K::enumeration, "Enum parse error", 4},
        {"enum hex overflow", h10 + "enum E\n    a = 0xFFFFFFFF\nend\n", K::enumeration, "Enum parse error", 4},
        {"enum value named end", h10 + "enum E\n    a = 0,\tend\nend\n", K::enumeration, "Enum parse error", 4},
        {"enum empty piece", h10 + "enum E\n    a = 1,, b\nend\n", K::enumeration, "Enum parse error", 4},
        {"enum leading zero", h10 + "enum E\n    a = 03\nend\n", K::enumeration, "Enum parse error", 4},
        // --- constants (robdef.md §7)
        {"int32 constant out of range", h10 + "constant int32 C 2147483648\n", K::constant,
         "Invalid constant definition", 3},
        {"double constant in hex", h10 + "constant double C 0x10\n", K::constant, "Invalid constant definition", 3},
        {"bool constant", h10 + "constant bool C 1\n", K::constant, "Invalid constant definition", 3},
        {"multidim constant", h10 + "constant double[*] C {1}\n", K::constant, "Invalid constant definition", 3},
        {"string array constant", h10 + "constant string[] C {\"a\"}\n", K::constant, "Invalid constant definition",
         3},
        {"unescaped quote in a string constant", h10 + "constant string C \"a\"b\"\n", K::constant,
         "Invalid constant definition", 3},
        {"unknown escape in a string constant", h10 + "constant string C \"\\q\"\n", K::constant,
         "Invalid constant definition", 3},
        {"trailing comma in an array constant", h10 + "constant int32[] C {1, 2,}\n", K::constant,
         "Invalid constant definition", 3},
        {"single constant out of range", h10 + "constant single C 3.5e38\n", K::constant,
         "Invalid constant definition", 3},
        {"double constant out of range", h10 + "constant double C 1e400\n", K::constant,
         "Invalid constant definition", 3},
        {"dotted constant name", h10 + "constant int16 DRIVE.STRAIGHT 1\n", K::constant,
         "Invalid constant definition", 3},
        {"constant without value", h10 + "constant int32 C\n", K::constant, "Invalid constant definition", 3},
        {"number for a string constant", h10 + "constant string C 12\n", K::constant, "Invalid constant definition",
         3},
        {"struct constant without colon", h10 + "constant struct C {a b}\n", K::constant,
         "Invalid constant definition", 3},
        {"uint8 constant above 255", h10 + "constant uint8 C 256\n", K::constant, "Invalid constant definition", 3},
        {"int8 constant of two digits", h10 + "constant int8 C 10\n", K::constant, "Invalid constant definition", 3},
        {"negative int8 constant", h10 + "constant int8 C -1\n", K::constant, "Invalid constant definition", 3},
        {"uint8 array constant with 20", h10 + "constant uint8[] C {1, 20}\n", K::constant,
         "Invalid constant definition", 3},
        {"int8 constant in an object", h10 + "object O\n    constant int8 C 0x1\nend\n", K::constant,
         "Invalid constant definition", 4},
    };
    for (const auto& c : cases) {
        INFO(c.what << "\n" << c.text);
        auto r = parse_service_definition_report(c.text, "t.robdef");
        INFO(dump(r.diagnostics));
        REQUIRE_FALSE(r.ok());
        const Diagnostic& d = r.diagnostics.back();
        CHECK(d.severity == Severity::error);
        CHECK(d.message == c.message);
        CHECK(d.line == c.line);
        CHECK(d.kind == c.kind);
        CHECK(d.file == "t.robdef");
    }
    CHECK(cases.size() >= 60);
}

TEST_CASE("parse_service_definition returns the error as an RRError") {
    auto r = parse_service_definition("service a.b\nfoo bar\n", "x.robdef");
    REQUIRE_FALSE(r);
    CHECK(r.error().type == rr::MessageErrorType::ServiceDefinitionError);
    CHECK(r.error().name == "RobotRaconteur.ServiceDefinitionError");
    CHECK(r.error().message == "x.robdef:2: Parse error");
}

TEST_CASE("statements, docstrings and locations") {
    auto d = parse_ok(
        "## The service\n"
        "service experimental.t\n"
        "\n"
        "stdver 0.10\n"
        "import experimental.base\n"
        "using experimental.base.Thing\n"
        "using experimental.base.Other as Alias\n"
        "## an error\n"
        "exception Broken\n"
        "constant string Greeting \"hi \\\"there\\\" \\u00e9\\n\"\n"
        "# comment clears docs\n"
        "struct S\n"
        "    field Thing t\n"
        "    field Alias[] a\n"
        "end\n");
    CHECK(d.name == "experimental.t");
    CHECK(d.docstring == std::vector<std::string>{" The service"});
    REQUIRE(d.stdver);
    CHECK(d.stdver->to_string() == "0.10");
    CHECK_FALSE(d.version_from_option);
    CHECK(d.location.line == 2);
    CHECK(d.location.file == "t.robdef");
    CHECK(d.imports == std::vector<std::string>{"experimental.base"});
    CHECK(d.import_lines == std::vector<int>{5});
    REQUIRE(d.usings.size() == 2);
    CHECK(d.usings[0].unqualified_name == "Thing");
    CHECK(d.usings[1].qualified_name == "experimental.base.Other");
    CHECK(d.usings[1].unqualified_name == "Alias");
    REQUIRE(d.exceptions.size() == 1);
    CHECK(d.exceptions[0].docstring == std::vector<std::string>{" an error"});
    CHECK(d.exceptions[0].location.line == 9);
    REQUIRE(d.constants.size() == 1);
    CHECK(d.constants[0].value == "\"hi \\\"there\\\" \\u00e9\\n\"");
    const auto& s = d.structures.at(0);
    CHECK(s.docstring.empty());
    CHECK(s.location.line == 12);
    CHECK(s.members.at(0).type.type_name == "experimental.base.Thing");  // using expanded
    CHECK(s.members.at(1).type.type_name == "experimental.base.Other");
    CHECK(s.members.at(1).type.array == ArrayKind::array);
    CHECK(s.members.at(1).kind == MemberKind::field);
    CHECK(s.members.at(1).location.line == 14);
}

TEST_CASE("member modifiers, including arguments and unknown ones") {
    auto d = parse_ok(
        "service a.b\n"
        "object O\n"
        "    constant int32 C 5\n"
        "    property double p [readonly, nolock]\n"
        "    function void f(int32 a) [unknown, unknown_3(23, 45.8e-5, unknown_modifier_hello)]\n"
        "    pipe double[] q [ readonly,]\n"
        "    wire double w [writeonly]\n"
        "end\n");
    const auto& o = d.objects.at(0);
    CHECK(o.members.at(0).modifiers == std::vector<std::string>{"readonly", "nolock"});
    CHECK(o.members.at(0).direction() == MemberDirection::readonly);
    CHECK(o.members.at(1).modifiers ==
          std::vector<std::string>{"unknown", "unknown_3(23, 45.8e-5, unknown_modifier_hello)"});
    CHECK(o.members.at(2).modifiers == std::vector<std::string>{"readonly"});
    CHECK(o.members.at(3).direction() == MemberDirection::writeonly);
}

TEST_CASE("line continuation, CRLF, tabs and blank before parentheses") {
    auto d = parse_ok(
        "service a.b\r\n"
        "\r\n"
        "object O\r\n"
        "\twire int32 \\\r\n"
        "\t\tw\r\n"
        "    function void f (double a,\tint32[] b )\r\n"
        "    # a comment ending in a backslash \\\r\n"
        "    event e(double 9, string end)\r\n"
        "    property double after\r\n"
        "end\r\n");
    const auto& o = d.objects.at(0);
    REQUIRE(o.members.size() == 4);
    CHECK(o.members[0].kind == MemberKind::wire);
    CHECK(o.members[0].name == "w");
    CHECK(o.members[1].parameters.size() == 2);
    CHECK(o.members[1].parameters[1].name == "b");
    CHECK(o.members[2].parameters[0].name == "9");  // parameter names are not checked (robdef.md §4)
    CHECK(o.members[3].location.line == 9);
}

TEST_CASE("enums: hex, negative, implicit, several per line, trailing comma, empty") {
    auto d = parse_ok(
        "service a.b\n"
        "stdver 0.10\n"
        "enum Flags\n"
        "    ## first\n"
        "    none = 0,\n"
        "    one = 0x1, two = 0x2,\ttwo_more,\n"
        "    neg = -5, neg_next,\n"
        "    low = -0x80000000,\n"
        "    readonly = 100,\n"
        "end\n"
        "enum Empty\n"
        "end\n");
    const auto& e = d.enums.at(0);
    REQUIRE(e.values.size() == 8);
    CHECK(e.values[0].docstring == std::vector<std::string>{" first"});
    CHECK(e.values[2].value == 2);
    CHECK(e.values[2].hex);
    CHECK(e.values[3].value == 3);
    CHECK(e.values[3].implicit);
    CHECK(e.values[3].hex);
    CHECK(e.values[4].value == -5);
    CHECK(e.values[5].value == -4);
    CHECK(e.values[6].value == INT32_MIN);
    CHECK(e.values[7].name == "readonly");
    CHECK(e.values[6].line == 8);
    CHECK(d.enums.at(1).values.empty());
}

TEST_CASE("type forms") {
    auto t = [](std::string_view s) {
        auto r = parse_type(s);
        INFO(s);
        REQUIRE(r);
        return *r;
    };
    CHECK(t("double").base == rr::DataTypes::double_t);
    auto a = t("double[]");
    CHECK((a.array == ArrayKind::array && a.array_var_length && a.array_length.empty()));
    auto f = t("int32[3]");
    CHECK((!f.array_var_length && f.array_length == std::vector<std::int32_t>{3}));
    auto b = t("uint8[16-]");
    CHECK((b.array_var_length && b.array_length == std::vector<std::int32_t>{16}));
    auto m = t("double[*]");
    CHECK((m.array == ArrayKind::multidimarray && m.array_var_length && m.array_length.empty()));
    auto m1 = t("double[3,]");
    CHECK((m1.array == ArrayKind::multidimarray && m1.array_length == std::vector<std::int32_t>{3}));
    CHECK(m1.to_string() == "double[3,]");
    auto m2 = t("double[2,3,4]{list}");
    CHECK(m2.array_length == std::vector<std::int32_t>{2, 3, 4});
    CHECK(m2.container == ContainerKind::list);
    auto z = t("double[0]");
    CHECK((z.array_var_length && z.array_length.empty()));
    CHECK(z.to_string() == "double[]");
    CHECK(t("double[03]").array_length == std::vector<std::int32_t>{3});
    auto n = t("experimental.x.Pod[*] name");
    CHECK(n.base == rr::DataTypes::namedtype_t);
    CHECK(n.type_name == "experimental.x.Pod");
    CHECK(n.name == "name");
    CHECK(t("varvalue{string}").container == ContainerKind::map_string);
    CHECK(t("T{generator}").container == ContainerKind::generator);
    CHECK(t("varobject{int32}").base == rr::DataTypes::varobject_t);
    for (auto bad : {"", "1x", "double[", "double[*-]", "double[3][3]", "double{}", "double{x}{y}", "double x y",
                     "double[2,3,]"}) {
        INFO(bad);
        CHECK_FALSE(parse_type(bad));
    }
    CHECK(parse_type("double{foo}").error().message == "Could not parse type \"double{foo}\": invalid container type");
}

TEST_CASE("legacy syntax: option version, end struct/object, option constant, option pipe unreliable") {
    auto r = parse_service_definition_report(
        "#Service to provide sample interface\n"
        "service experimental.legacy\n"
        "\n"
        "option version 0.8\n"
        "\n"
        "struct S\n"
        "    field uint8[] Data\n"
        "end struct\n"
        "\n"
        "object O\n"
        "    option constant int16 SPEED 100\n"
        "    option pipe p unreliable\n"
        "    pipe S p\n"
        "end object\n",
        "legacy.robdef");
    REQUIRE(r.ok());
    REQUIRE(r.diagnostics.size() == 3);
    for (const auto& w : r.diagnostics) {
        CHECK(w.severity == Severity::warning);
        CHECK(w.kind == DiagnosticKind::deprecated);
        CHECK(w.message == "option keyword is deprecated");
    }
    CHECK(r.diagnostics[0].line == 4);
    CHECK(r.diagnostics[2].line == 12);
    const auto& d = *r.definition;
    REQUIRE(d.stdver);
    CHECK(d.stdver->to_string() == "0.8");
    CHECK(d.version_from_option);
    CHECK(d.options == std::vector<std::string>{"version 0.8"});
    const auto& o = d.objects.at(0);
    CHECK(o.options.at(0) == "constant int16 SPEED 100");
    CHECK(pipe_is_unreliable(o, o.members.at(0)));
}

TEST_CASE("empty entries, struct constants, generators, empty file") {
    auto d = parse_ok(
        "service a.b\n"
        "stdver 0.10\n"
        "constant int32 A 1\n"
        "constant double[] B {1.5, -.5, 1., 2e3}\n"
        "constant uint32 WRAP -1\n"
        "constant int8 I8 7\n"
        "constant uint64[] H {0xFFFFFFFFFFFFFFFF, +0x10}\n"
        "constant struct S1 {a: A, b: B}\n"
        "constant struct S2 {}\n"
        "struct Empty\n"
        "end\n"
        "pod EmptyPod\n"
        "end\n"
        "object EmptyObject\n"
        "end\n"
        "object G\n"
        "    function double{generator} g1()\n"
        "    function void g2(int32 a, double{generator} b)\n"
        "    function Empty{generator} g3(double{generator} b)\n"
        "end\n");
    CHECK(d.constants.size() == 7);
    CHECK(d.constants[5].type.type_name == "struct");
    CHECK(d.structures.at(0).members.empty());
    CHECK(d.objects.at(1).members.at(0).is_generator());
    CHECK(d.objects.at(1).members.at(1).is_generator());

    auto empty = parse_ok("# only a comment\n\n");
    CHECK(empty.name.empty());
}

TEST_CASE("constant value checks") {
    auto t = [](std::string_view s) { return parse_type(s).value(); };
    // 8-bit integers: one digit per value, as the official parser (which reads them as characters).
    CHECK(is_valid_constant_value(t("int8"), "0"));
    CHECK(is_valid_constant_value(t("uint8"), " 9 "));
    CHECK_FALSE(is_valid_constant_value(t("int8"), "10"));
    CHECK_FALSE(is_valid_constant_value(t("int8"), "-1"));
    CHECK_FALSE(is_valid_constant_value(t("int8"), "+1"));
    CHECK_FALSE(is_valid_constant_value(t("int8"), "-0"));
    CHECK_FALSE(is_valid_constant_value(t("uint8"), "0x1"));
    CHECK_FALSE(is_valid_constant_value(t("uint8"), "a"));
    CHECK(is_valid_constant_value(t("uint8[]"), "{1, 2, 3}"));
    CHECK(is_valid_constant_value(t("int8[2]"), "{ }"));
    CHECK_FALSE(is_valid_constant_value(t("uint8[]"), "{1, 20}"));
    CHECK_FALSE(is_valid_constant_value(t("int8[]"), "{-1}"));
    CHECK(is_valid_constant_value(t("int16"), "-32768"));
    CHECK(is_valid_constant_value(t("uint16"), "-65535"));  // unsigned types wrap negative values
    CHECK_FALSE(is_valid_constant_value(t("uint16"), "-65536"));
    CHECK(is_valid_constant_value(t("int32"), "-0x80000000"));
    CHECK_FALSE(is_valid_constant_value(t("int32"), "0x80000000"));
    CHECK(is_valid_constant_value(t("int64"), "-9223372036854775808"));
    CHECK_FALSE(is_valid_constant_value(t("int64"), "9223372036854775808"));
    CHECK(is_valid_constant_value(t("single"), "1e-50"));
    CHECK(is_valid_constant_value(t("double"), ".5e+3"));
    CHECK_FALSE(is_valid_constant_value(t("double"), "01.5"));
    CHECK_FALSE(is_valid_constant_value(t("double"), "inf"));
    CHECK(is_valid_constant_value(t("string"), "\"\\ud83d\\udE01 \\/ \\b\\f\\r\\t\""));
    CHECK_FALSE(is_valid_constant_value(t("string"), "\"\\u12\""));
    CHECK(is_valid_constant_value(t("double[]"), "{ }"));
    CHECK_FALSE(is_valid_constant_value(t("double{list}"), "{1}"));
    // A container on a string or struct constant is not checked (official parser).
    CHECK(is_valid_constant_value(t("string{list}"), "\"a\""));
    CHECK(is_valid_constant_value(t("struct{int32}"), "{a: b}"));
    CHECK_FALSE(is_valid_constant_value(t("string[]"), "\"a\""));
    auto f = parse_struct_constant_fields("{ a : b , c:d }");
    REQUIRE(f);
    REQUIRE(f->size() == 2);
    CHECK((*f)[1].name == "c");
    CHECK((*f)[1].constant_name == "d");
}

TEST_CASE("robdef: member kinds read with their article in messages") {
    using rr::robdef::MemberKind;
    CHECK(rr::robdef::with_article(rr::robdef::member_kind_keyword(MemberKind::event)) == "an event");
    CHECK(rr::robdef::with_article(rr::robdef::member_kind_keyword(MemberKind::objref)) == "an objref");
    CHECK(rr::robdef::with_article(rr::robdef::member_kind_keyword(MemberKind::wire)) == "a wire");
    CHECK(rr::robdef::with_article(rr::robdef::member_kind_keyword(MemberKind::property)) == "a property");
}

// Cases where the official parser is followed although its behaviour looks accidental (robdef.md
// §2.2, §4.1, §1.1); test/interop/robdef_agreement.py compares these with the official library.
TEST_CASE("official behaviour followed: option above stdver, objref array with container, BOM in text") {
    SECTION("an option above stdver >= 0.9.2 is accepted with the deprecation warning") {
        auto r = parse_service_definition_report("service a.b\noption foo\nstdver 0.10\n", "t.robdef");
        REQUIRE(r.ok());
        REQUIRE(r.diagnostics.size() == 1);
        CHECK(r.diagnostics[0].severity == Severity::warning);
        CHECK(r.diagnostics[0].line == 2);
        CHECK(r.definition->options == std::vector<std::string>{"foo"});
        CHECK(r.definition->stdver == Version{0, 10, 0, 0});
        // ... but not below it, and not as `option version` next to stdver.
        CHECK_FALSE(parse_service_definition_report("service a.b\nstdver 0.10\noption foo\n", "t").ok());
        CHECK_FALSE(parse_service_definition_report("service a.b\noption version 0.9\nstdver 0.10\n", "t").ok());
    }
    SECTION("objref T[] with a container is accepted; its key type follows the container") {
        auto d = parse_ok(
            "service a.b\nstdver 0.10\nobject P\nend\nobject O\n"
            "    objref P[]{int32} a\n    objref P[]{string} b\n    objref P[]{list} c\n    objref varobject[]{int32} d\n"
            "    objref P[] e\n    objref P[0-] f\n    objref P{string} g\n    objref P h\nend\n");
        const auto& m = d.objects.at(1).members;
        REQUIRE(m.size() == 8);
        CHECK(m[0].type.array == ArrayKind::array);
        CHECK(m[0].type.container == ContainerKind::map_int32);
        CHECK(objref_index_kind(m[0].type) == ObjRefIndexKind::int32);
        CHECK(objref_index_kind(m[1].type) == ObjRefIndexKind::string);
        CHECK(objref_index_kind(m[2].type) == ObjRefIndexKind::int32);
        CHECK(objref_index_kind(m[3].type) == ObjRefIndexKind::int32);
        CHECK(objref_index_kind(m[4].type) == ObjRefIndexKind::int32);
        CHECK(objref_index_kind(m[5].type) == ObjRefIndexKind::int32);
        CHECK(objref_index_kind(m[6].type) == ObjRefIndexKind::string);
        CHECK(objref_index_kind(m[7].type) == ObjRefIndexKind::none);
        CHECK(m[0].type.to_string() == "P[]{int32}");
    }
    SECTION("a byte-order mark in text is not ASCII (the file readers strip it, the parser does not)") {
        auto r = parse_service_definition_report("\xEF\xBB\xBFservice a.b\nstdver 0.10\n", "t.robdef");
        REQUIRE_FALSE(r.ok());
        CHECK(r.diagnostics.back().message == kBomInText + "1)");
        CHECK(r.diagnostics.back().line == 1);
    }
}

// Issue 40: a robdef with a UTF-8 byte-order mark. The official verdict, run with robotraconteur 1.2.9
// (the .venv, Python) on "\xEF\xBB\xBFservice t.bom\nstdver 0.10\nstruct S\n    field int32 x\nend\n":
//   ServiceDefinition.FromString(text), RegisterServiceType(open(path).read()) -> refused,
//     "Parse error: Service definition must contain only ASCII characters" (the mark is not named);
//   RegisterServiceTypeFromFile(path), RegisterServiceTypesFromFiles([path]),
//     RegisterServiceType(ReadServiceDefinitionFile(path)) -> accepted (utf-8-sig drops the mark);
//   RobotRaconteurGen --verify-robdef reads files with ReadFile, which skips a leading EF BB BF (source).
// So the official *text* parser refuses it and the official *file* readers and verifier accept it. We
// agree with both: the parser refuses it in text with the official message plus what the bytes are;
// reading a file (rr-robdef check) drops one leading mark, as the official file readers do, and warns
// that the text itself would be refused (RegisterServiceType), which is how a user meets the problem.
TEST_CASE("a byte-order mark: refused in text naming it, dropped from the start of a file with a warning") {
    SECTION("in text: the official message, then what the bytes are and where") {
        auto r = parse_service_definition_report("service a.b\nstdver 0.10\n# a \xEF\xBB\xBF\n", "t.robdef");
        REQUIRE_FALSE(r.ok());
        CHECK(r.diagnostics.back().message == kBomInText + "5)");
        CHECK(r.diagnostics.back().line == 3);
        // Other non-ASCII bytes keep the official message alone.
        auto utf8 = parse_service_definition_report("service a.b\n# caf\xC3\xA9\n", "t.robdef");
        REQUIRE_FALSE(utf8.ok());
        CHECK(utf8.diagnostics.back().message == "Service definition must contain only ASCII characters");
    }
    SECTION("a file: one leading mark dropped with a warning that names it; the text parses") {
        auto f = definition_file_text("\xEF\xBB\xBFservice a.b\nstdver 0.10\n", "t.robdef");
        CHECK(f.text == "service a.b\nstdver 0.10\n");
        REQUIRE(f.diagnostics.size() == 1);
        const auto& w = f.diagnostics[0];
        CHECK(w.severity == Severity::warning);
        CHECK(w.file == "t.robdef");
        CHECK(w.line == 1);
        CHECK_THAT(w.message, Catch::Contains("UTF-8 byte-order mark (bytes EF BB BF)"));
        CHECK_THAT(w.message, Catch::Contains("RegisterServiceType"));
        CHECK(format_diagnostic(w).rfind("t.robdef:1: warning: the file starts with a UTF-8 byte-order mark", 0) == 0);
        CHECK(parse_service_definition_report(f.text, "t.robdef").ok());
    }
    SECTION("a file: nothing else is dropped; a second mark, or one after a blank line, is refused") {
        auto plain = definition_file_text("service a.b\n", "t.robdef");
        CHECK(plain.text == "service a.b\n");
        CHECK(plain.diagnostics.empty());
        auto twice = definition_file_text("\xEF\xBB\xBF\xEF\xBB\xBFservice a.b\n", "t.robdef");
        CHECK(twice.diagnostics.size() == 1);
        auto r = parse_service_definition_report(twice.text, "t.robdef");
        REQUIRE_FALSE(r.ok());
        CHECK(r.diagnostics.back().message == kBomInText + "1)");
        auto later = definition_file_text("\n\xEF\xBB\xBFservice a.b\n", "t.robdef");
        CHECK(later.diagnostics.empty());
        auto r2 = parse_service_definition_report(later.text, "t.robdef");
        REQUIRE_FALSE(r2.ok());
        CHECK(r2.diagnostics.back().line == 2);
        CHECK(definition_file_text("", "t.robdef").text.empty());
        CHECK(definition_file_text("\xEF\xBB", "t.robdef").text == "\xEF\xBB");  // half a mark stays
    }
}
