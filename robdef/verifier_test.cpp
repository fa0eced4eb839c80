// Verifier tests: every rule of robdef.md §10 with the official message text, the kind, and the
// physical line; warnings; and valid tricky forms that must verify cleanly.
#include <catch2/catch.hpp>

#include "robdef/parser.hpp"
#include "robdef/test_support.hpp"
#include "robdef/verifier.hpp"

using namespace rr::robdef;
using rr::robdef::test::dump;

namespace {

// A base service other cases import.
const char* const kBase =
    "service c.d\n"
    "stdver 0.10\n"
    "constant int32 K 1\n"
    "enum Mode\n"
    "    a = 0\n"
    "end\n"
    "exception Failure\n"
    "struct T\n"
    "    field double x\n"
    "end\n"
    "pod P\n"
    "    field double x\n"
    "end\n"
    "namedarray N\n"
    "    field double x\n"
    "end\n"
    "object Base\n"
    "    property double value\n"
    "end\n";

// Parses `text` (file "t.robdef") plus the given extra texts and verifies them as one set.
std::vector<Diagnostic> verify_texts(const std::string& text, std::vector<std::string> extra = {kBase}) {
    std::vector<ServiceDefinition> defs;
    auto r = parse_service_definition_report(text, "t.robdef");
    INFO(text << "\n" << dump(r.diagnostics));
    REQUIRE(r.ok());
    defs.push_back(std::move(*r.definition));
    for (std::size_t i = 0; i < extra.size(); ++i) {
        auto x = parse_service_definition_report(extra[i], "extra" + std::to_string(i) + ".robdef");
        INFO(extra[i] << "\n" << dump(x.diagnostics));
        REQUIRE(x.ok());
        defs.push_back(std::move(*x.definition));
    }
    return verify_service_definitions(defs);
}

struct VerifyCase {
    const char* what;
    std::string text;
    DiagnosticKind kind;
    std::string message;
    int line;
};

}  // namespace

TEST_CASE("invalid definitions fail verification with the official message at the right line") {
    using K = DiagnosticKind;
    const std::string h = "service a.b\nstdver 0.10\nimport c.d\n";  // lines 1-3
    const std::string o = h + "object O\n";                              // line 4
    const std::vector<VerifyCase> cases{
        // --- names (robdef.md §8)
        {"reserved entry name", h + "struct object\nend\n", K::name, "Name \"object\" is reserved", 4},
        {"this/self/Me", o + "    property double self\nend\n", K::name,
         "The names \"this\", \"self\", and \"Me\" are reserved", 5},
        {"get_ prefix", o + "    property double get_x\nend\n", K::name, "Name \"get_x\" is reserved or invalid", 5},
        {"rr prefix, any case", h + "struct RRate\nend\n", K::name, "Name \"RRate\" is reserved or invalid", 4},
        {"async_ prefix on a function", o + "    function void Async_go()\nend\n", K::name,
         "Name \"Async_go\" is reserved or invalid", 5},
        {"member name ending in underscore", o + "    property double x_\nend\n", K::name, "Name \"x_\" is invalid",
         5},
        {"member name starting with a digit", o + "    property double 1x\nend\n", K::name,
         "Name \"1x\" is invalid", 5},
        {"robotraconteur service prefix", "service robotraconteur.foo\n", K::name,
         "Name \"robotraconteur.foo\" is reserved or invalid", 1},
        {"_signed suffix", "service foo.bar_signed\n", K::name,
         "Service definition names ending with \"_signed\" are reserved", 1},
        {"empty definition", "# nothing\n", K::name, "name must not be empty", 0},
        {"dotted exception name", h + "exception e.f\n", K::name, "Name \"e.f\" is invalid", 4},
        {"enum value name ending in underscore", h + "enum E\n    a_ = 1\nend\n", K::name,
         "Name \"a_\" is invalid", 5},
        {"reserved constant name", h + "constant int32 end 1\n", K::name, "Name \"end\" is reserved", 4},
        {"invalid using alias", h + "using c.d.T as rrT\n", K::name, "Name \"rrT\" is reserved or invalid", 4},
        // --- imports (robdef.md §10 rule 3)
        {"unknown import", h + "import x.y\n", K::import, "Service definition \"x.y\" not found", 4},
        {"self import", "service a.b\nimport a.b\n", K::import, "Recursive imports between \"a.b\" and \"a.b\"", 1},
        // --- unique names
        {"duplicate high-level names", h + "struct S\nend\nobject S\nend\n", K::duplicate,
         "Service definition \"a.b\" contains multiple high level names \"S\"", 6},
        {"constant and enum with one name", h + "constant int32 E 1\nenum E\n    a = 1\nend\n", K::duplicate,
         "Service definition \"a.b\" contains multiple high level names \"E\"", 5},
        {"duplicate object members", o + "    property double x\n    function void x()\nend\n", K::duplicate,
         "Object \"O\" contains multiple members named \"x\"", 6},
        {"duplicate struct fields", h + "struct S\n    field double x\n    field int32 x\nend\n", K::duplicate,
         "Structure \"S\" contains multiple members named \"x\"", 6},
        {"struct constant named like another constant", h + "struct S\n    constant int32 C 1\n    constant int32 C 2\nend\n",
         K::duplicate, "Struct \"S\" contains multiple members named \"C\"", 6},
        // --- using (rule 7)
        {"using of a missing entry", h + "using c.d.Missing\n", K::using_alias, "Using \"c.d.Missing\" is invalid", 4},
        {"using of a service not imported", "service a.b\nstdver 0.10\nusing c.d.T\n", K::using_alias,
         "Using \"c.d.T\" is invalid", 3},
        // --- types (robdef.md §6.2, §6.3)
        {"unknown type", o + "    property Foo x\nend\n", K::type, "could not resolve named type \"Foo\"", 5},
        {"own service fully qualified", h + "struct S\nend\nobject O\n    property a.b.S x\nend\n", K::type,
         "could not resolve named type \"a.b.S\"", 7},
        {"imported type without import", "service a.b\nstdver 0.10\nobject O\n    property c.d.T x\nend\n", K::type,
         "could not resolve named type \"c.d.T\"", 4},
        {"string array", o + "    property string[] x\nend\n", K::type,
         "Invalid Robot Raconteur data type \"string[] value\"", 5},
        {"struct array", o + "    property c.d.T[] x\nend\n", K::type,
         "Invalid Robot Raconteur data type \"c.d.T[] value\"", 5},
        {"enum array as a parameter", o + "    function void f(c.d.Mode[] m)\nend\n", K::type,
         "Invalid Robot Raconteur data type \"c.d.Mode[] m\"", 5},
        {"void property", o + "    property void x\nend\n", K::type, "Invalid Robot Raconteur data type \"void value\"",
         5},
        {"structure keyword", o + "    property structure x\nend\n", K::type,
         "Invalid Robot Raconteur data type \"structure value\"", 5},
        {"object type as a value", o + "    property c.d.Base x\nend\n", K::type,
         "Invalid Robot Raconteur data type \"c.d.Base value\"", 5},
        {"void array return", o + "    function void[] f()\nend\n", K::type,
         "Invalid Robot Raconteur data type \"void[]\"", 5},
        {"generator on a property", o + "    property double{generator} x\nend\n", K::type,
         "Invalid Robot Raconteur data type \"double{generator} value\"", 5},
        {"generator on a callback", o + "    callback double{generator} c()\nend\n", K::type,
         "Invalid Robot Raconteur data type \"double{generator}\"", 5},
        // --- generators, parameters
        {"generator parameter not last", o + "    function void f(double{generator} a, double b)\nend\n", K::type,
         "Invalid Robot Raconteur data type \"double{generator} a\"", 5},
        {"void generator return", o + "    function void{generator} f()\nend\n", K::member,
         "Generator return must not be void", 5},
        {"generator parameter with plain return", o + "    function double f(double{generator} a)\nend\n",
         K::member, "Generator return must use generator container", 5},
        {"duplicate parameter names", o + "    function void f(double a, int32 a)\nend\n", K::member,
         "Parameters must have unique names", 5},
        // --- memory
        {"memory of varvalue", o + "    memory varvalue[] m\nend\n", K::member,
         "Memory member must be numeric, pod, or namedarray", 5},
        {"memory scalar", o + "    memory double m\nend\n", K::member, "Memory member must be array or multidimarray",
         5},
        {"memory fixed", o + "    memory double[3] m\nend\n", K::member, "Memory member must not be fixed size", 5},
        {"memory bounded", o + "    memory double[3-] m\nend\n", K::member, "Memory member must not be fixed size", 5},
        {"memory fixed multidim", o + "    memory c.d.P[2,2] m\nend\n", K::member,
         "Memory member must not be fixed size", 5},
        // --- objref
        {"objref unknown", o + "    objref Missing o\nend\n", K::member, "Unknown object type \"Missing\"", 5},
        {"objref of a struct", o + "    objref c.d.T t\nend\n", K::member, "Unknown object type \"c.d.T\"", 5},
        // --- pods
        {"pod string field", h + "pod Q\n    field string s\nend\n", K::pod,
         "Pods must only contain numeric, pod, and namedarray types", 5},
        {"pod struct field", h + "pod Q\n    field c.d.T s\nend\n", K::pod,
         "Pods must only contain numeric, namedarray, pod types", 5},
        {"pod container", h + "pod Q\n    field double{list} s\nend\n", K::pod, "Pods must not use containers", 5},
        {"pod variable array", h + "pod Q\n    field double[] s\nend\n", K::pod,
         "Pods must have fixed or finite length arrays", 5},
        {"pod any-shape multidim", h + "pod Q\n    field c.d.P[*] s\nend\n", K::pod,
         "Pods must have fixed or finite length arrays", 5},
        {"pod recursion", h + "pod Q\n    field R r\nend\npod R\n    field Q q\nend\n", K::pod,
         "Recursive namedarray/pod detected in \"R\"", 4},
        // --- namedarrays
        {"namedarray string field", h + "namedarray M\n    field string s\nend\n", K::namedarray,
         "NamedArrays must only contain numeric and namedarray types: s", 5},
        {"namedarray pod field", h + "namedarray M\n    field c.d.P p\nend\n", K::namedarray,
         "NamedArrays must only contain numeric and namedarray types: p", 5},
        {"namedarray container", h + "namedarray M\n    field double{list} x\nend\n", K::namedarray,
         "NamedArrays may not use containers: x", 5},
        {"namedarray bounded array", h + "namedarray M\n    field double[3-] x\nend\n", K::namedarray,
         "NamedArray fields must be scalars or fixed arrays", 5},
        {"namedarray fixed multidim", h + "namedarray M\n    field double[2,2] x\nend\n", K::namedarray,
         "NamedArray fields must be scalars or fixed arrays", 5},
        {"namedarray mixed element types", h + "namedarray M\n    field double x\n    field single y\nend\n",
         K::namedarray, "Invalid namedarray \"M\" namedarray must contain same numeric type: M", 4},
        {"namedarray mixed through nesting", h + "namedarray M\n    field single y\n    field c.d.N n\nend\n",
         K::namedarray, "Invalid namedarray \"M\" namedarray must contain same numeric type: M", 4},
        {"empty namedarray", h + "namedarray M\nend\n", K::namedarray,
         "Invalid namedarray \"M\" namedarray must not be empty", 4},
        {"namedarray recursion", h + "namedarray M\n    field M m\nend\n", K::namedarray,
         "Invalid namedarray \"M\" Recursive namedarray detected in M", 4},
        // --- constants
        {"struct constant with a missing field constant", h + "constant struct S {a: missing}\n", K::constant,
         "Error in constant S: struct field missing not found", 4},
        {"struct constant referring to itself", h + "constant struct S {a: S}\n", K::constant,
         "Error in constant S: recursive struct not allowed", 4},
        {"struct constants in a cycle", h + "constant struct S1 {a: S2}\nconstant struct S2 {b: S1}\n", K::constant,
         "Error in constant S2: recursive struct not allowed", 4},
        {"struct constant field name invalid", h + "constant int32 A 1\nconstant struct S {rr: A}\n", K::name,
         "Name \"rr\" is reserved or invalid", 5},
        {"struct constant in a block referring to a top-level constant",
         h + "constant int32 A 1\nstruct S\n    constant struct C {a: A}\nend\n", K::constant,
         "Error in constant C: struct field A not found", 6},
        {"legacy option constant of a named type", "service a.b\nobject O\n    option constant T x {a: b}\nend\n",
         K::constant, "Error in constant x", 2},
        {"legacy option constant that does not parse", "service a.b\noption constant int32 x.y 1\n", K::constant,
         "could not parse constant \"constant int32 x.y 1\"", 2},
        // --- versions (robdef.md §9)
        {"modifiers need 0.9", "service a.b\noption version 0.8\nobject O\n    property double x [readonly]\nend\n",
         K::version, "Service definition standard version 0.9 or greater required for Member Modifiers", 4},
        {"object constants need 0.9", "service a.b\noption version 0.8\nobject O\n    constant int32 C 1\nend\n",
         K::version, "Service definition standard version 0.9 or greater required for \"constant\" keyword", 4},
        {"enums need 0.9", "service a.b\noption version 0.8\nenum E\n    a = 1\nend\n", K::version,
         "Service definition standard version 0.9 or greater required for \"enum\" keyword", 3},
        {"newer than the library", "service a.b\nstdver 1.3\n", K::version,
         "Service a.b requires newer version of Robot Raconteur", 2},
        {"imported definition with a higher version", "service a.b\nstdver 0.9\nimport c.d\n", K::version,
         "Imported service definition c.d has a higher Service Definition standard version than a.b", 3},
        // --- implements (rule 10)
        {"implements unknown object", o + "    implements Missing\nend\n", K::implements,
         "Object \"a.b.Missing not found to implement in a.b.O", 5},
        {"implements unknown service", o + "    implements x.y.Z\nend\n", K::implements,
         "Service definition \"x.y\" not found to implement in a.b.O", 5},
        {"implements missing object of an imported service", o + "    implements c.d.Missing\nend\n", K::implements,
         "Object \"c.d.Missing\" not found to implement", 5},
        {"implements itself", o + "    implements O\nend\n", K::implements,
         "Recursive implements between \"a.b.O\" and \"a.b.O\"", 5},
        {"implements cycle", h + "object O\n    implements Q\nend\nobject Q\n    implements O\nend\n", K::implements,
         "Recursive implements between \"a.b.O\" and \"a.b.O\"", 4},
        {"inherited type not listed",
         h + "object A\nend\nobject B\n    implements A\nend\nobject C\n    implements B\nend\n", K::implements,
         "Object \"a.b.C\" does not implement inherited type \"a.b.A\"", 9},
        {"required member missing", o + "    implements c.d.Base\nend\n", K::implements,
         "Object \"O\" does not implement required member \"value\"", 4},
        {"implemented member of another type", o + "    implements c.d.Base\n    property int32 value\nend\n",
         K::implements, "Member \"value\" in object \"O\" does not match implemented member", 6},
        {"implemented member with other modifiers", o + "    implements c.d.Base\n    property double value [readonly]\nend\n",
         K::implements, "Member \"value\" in object \"O\" does not match implemented member", 6},
        {"implemented function with other parameter names",
         h + "object A\n    function void f(double a)\nend\nobject B\n    implements A\n    function void f(double b)\nend\n",
         K::implements, "Member \"f\" in object \"B\" does not match implemented member", 9},
        {"implemented member of another kind",
         h + "object A\n    wire double w\nend\nobject B\n    implements A\n    pipe double w\nend\n", K::implements,
         "Member \"w\" in object \"B\" does not match implemented member", 9},
    };
    for (const auto& c : cases) {
        INFO(c.what << "\n" << c.text);
        auto diags = verify_texts(c.text);
        INFO(dump(diags));
        auto it = std::find_if(diags.begin(), diags.end(), [](const Diagnostic& d) { return d.is_error(); });
        REQUIRE(it != diags.end());
        CHECK(it->message == c.message);
        CHECK(it->line == c.line);
        CHECK(it->kind == c.kind);
        CHECK(it->file == "t.robdef");
    }
    CHECK(cases.size() >= 60);
}

TEST_CASE("recursive imports and duplicate service names across files") {
    auto d = verify_texts("service a.b\nimport c.d\n", {"service c.d\nimport a.b\n"});
    REQUIRE(d.size() == 2);
    CHECK(d[0].message == "Recursive imports between \"c.d\" and \"a.b\"");
    CHECK(d[0].file == "t.robdef");
    CHECK(d[1].file == "extra0.robdef");

    auto dup = verify_texts("service c.d\n", {kBase});
    REQUIRE(dup.size() == 1);
    CHECK(dup[0].message == "Service definition \"c.d\" is defined more than once");
    CHECK(dup[0].kind == DiagnosticKind::import);
}

TEST_CASE("several errors are reported, not just the first") {
    auto d = verify_texts(
        "service a.b\nstdver 0.10\nobject O\n    property Foo x\n    property string[] y\n    objref Bar z\nend\n");
    REQUIRE(d.size() == 3);
    CHECK(d[0].line == 4);
    CHECK(d[1].line == 5);
    CHECK(d[2].line == 6);
}

TEST_CASE("modifier warnings") {
    auto d = verify_texts(
        "service a.b\n"
        "stdver 0.10\n"
        "object O\n"
        "    constant int32 K 3\n"
        "    property double p [readonly, writeonly]\n"
        "    property double q [nolock, nolockread]\n"
        "    function void f() [unknown, unknown_3(23, 45.8e-5, K, not_a_constant)]\n"
        "    objref O o [urgent]\n"
        "    pipe double r [unreliable, unreliable]\n"
        "    event e() [urgent, urgent]\n"
        "end\n");
    std::vector<std::string> got;
    for (const auto& x : d) {
        CHECK(x.severity == Severity::warning);
        CHECK(x.kind == DiagnosticKind::modifier);
        got.push_back(std::to_string(x.line) + " " + x.message);
    }
    CHECK(got == std::vector<std::string>{
                     "5 Invalid member modifier combination: [readonly,writeonly]",
                     "6 Invalid member modifier combination: [nolock,nolockread]",
                     "7 Unknown member modifier: [unknown]",
                     "7 Could not verify modifier parameters: [unknown_3(23, 45.8e-5, K, not_a_constant)]",
                     "7 Unknown member modifier: [unknown_3(23, 45.8e-5, K, not_a_constant)]",
                     "8 Unknown member modifier: [urgent]",
                     "9 Invalid member modifier combination: [unreliable]",
                     "10 Invalid member modifier combination: [urgent]",
                 });

    auto legacy = verify_texts("service a.b\nobject O\n    option pipe p unreliable\n    pipe double p [unreliable]\nend\n");
    REQUIRE(legacy.size() == 1);
    CHECK(legacy[0].message == "Invalid member modifier combination: [unreliable]");
}

TEST_CASE("tricky valid definitions verify without diagnostics") {
    const std::vector<std::pair<const char*, std::string>> ok{
        {"using-as, implements chain through using, struct constants, generators",
         "service a.b\n"
         "stdver 0.10\n"
         "import c.d\n"
         "using c.d.T as Thing\n"
         "using c.d.Base\n"
         "using c.d.Mode\n"
         "using c.d.K\n"
         "using c.d.Failure\n"
         "constant int32 ONE 1\n"
         "constant string NAME \"n\"\n"
         "constant struct INNER {one: ONE}\n"
         "constant struct OUTER {inner: INNER, name: NAME}\n"
         "struct S\n"
         "    constant int32 LOCAL 2\n"
         "    constant struct SC {l: LOCAL}\n"
         "    field Thing t\n"
         "    field S{list} children\n"
         "    field varvalue{string} extra\n"
         "    field varvalue[] quirk\n"
         "    field Mode mode\n"
         "    field c.d.N[2,2] grid\n"
         "end\n"
         "pod Q\n"
         "    field c.d.P[3-] ps\n"
         "    field c.d.N n\n"
         "    field double[2,3] m\n"
         "end\n"
         "namedarray V\n"
         "    field c.d.N a\n"
         "    field double[3] b\n"
         "end\n"
         "object A\n"
         "    implements Base\n"
         "    property double value\n"
         "    function Thing{generator} g1(int32 a, Q{generator} b)\n"
         "    function void g2(double{generator} b)\n"
         "    function Mode{generator} g3()\n"
         "    memory Q[] mq\n"
         "    memory V[*] mv\n"
         "    memory cdouble[] mc\n"
         "    objref varobject{string} anything\n"
         "    objref B[] bs\n"
         "    objref c.d.Base{int32} bases\n"
         "    callback double[] cb(int32 x)\n"
         "    event ev(double 9a, string end)\n"
         "end\n"
         "object B\n"
         "    implements A\n"
         "    implements c.d.Base\n"
         "    property double value\n"
         "    function Thing{generator} g1(int32 a, Q{generator} b)\n"
         "    function void g2(double{generator} b)\n"
         "    function Mode{generator} g3()\n"
         "    memory Q[] mq\n"
         "    memory V[*] mv\n"
         "    memory cdouble[] mc\n"
         "    objref varobject{string} anything\n"
         "    objref B[] bs\n"
         "    objref Base{int32} bases\n"
         "    callback double[] cb(int32 x)\n"
         "    event ev(double 9a, string end)\n"
         "    property double extra [readonly,nolock]\n"
         "end\n"},
        {"empty struct, pod, object, enum; recursive struct",
         "service a.b\nstdver 0.10\nenum E\nend\nstruct S\nend\npod P\nend\nobject O\nend\n"
         "struct R\n    field R next\nend\n"},
        {"legacy syntax without a version may use modifiers and import versioned files",
         "service a.b\nimport c.d\nobject O\n    property double x [readonly]\n    option constant int16 C -1\nend object\n"},
        {"service name segments after the first are not checked as a whole", "service foo.struct\n"},
        {"single-segment service name", "service foo\n"},
        {"RobotRaconteurTestService names skip the name check", "service RobotRaconteurTestService_x\n"},
    };
    for (const auto& [what, text] : ok) {
        INFO(what);
        auto d = verify_texts(text);
        INFO(dump(d));
        CHECK(d.empty());
    }
}
