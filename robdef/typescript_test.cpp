// rr-robdef ts (typescript.hpp): the JS type of every value kind as the wasm package gives it, member
// proxies by kind and direction, doc comments, imports between definitions, enum/constant values.
// wasm-client/test/typed_test.mjs type-checks the output with tsc and runs it against live services.
#include <catch2/catch.hpp>

#include "robdef/service_definition_set.hpp"
#include "robdef/test_support.hpp"
#include "robdef/typescript.hpp"

using namespace rr::robdef;
using rr::robdef::test::dump;

namespace {

ServiceDefinitionSet load(std::initializer_list<std::string_view> texts) {
    ServiceDefinitionSet set;
    int n = 0;
    for (auto t : texts) {
        auto r = set.add_text(t, "t" + std::to_string(n++) + ".robdef");
        REQUIRE(r);
    }
    auto diags = set.verify();
    INFO(dump(diags));
    REQUIRE_FALSE(has_errors(diags));
    return set;
}

bool has(const std::string& text, std::string_view needle) { return text.find(needle) != std::string::npos; }

// A type the generator could not map (enum values named `unknown` do not count).
bool has_unknown_type(const std::string& text) {
    return has(text, ": unknown") || has(text, "<unknown") || has(text, "unknown>") || has(text, "unknown |");
}

constexpr std::string_view kValues = R"(service t.values

stdver 0.10

## A color.
enum Color
    red = 0,
    green,
    blue = 0x10,
    minus = -5
end

constant string greeting "hi \"there\""
constant uint64 big 0xFFFFFFFFFFFFFFFF
constant int32[] small {1, +2, -3}
constant int32 one 1

## A struct
## whose comment has */ in it.
struct S
    constant string NAME "s"
    field double d
    field int64 i64
    field uint32 u32
    field bool b
    field cdouble c
    field string s
    field Color e
    field double[] da
    field uint64[3] ua
    field bool[] ba
    field csingle[] ca
    field int16[*] md
    field S nested
    field S{list} list
    field double{int32} by_int
    field string{string} by_name
    field varvalue any
    field P one_pod
    field P[] pods
    field P[*] pod_md
    field N na
    field N[] nas
end

pod P
    field int8 a
    field double[2] b
end

namedarray V
    field int64 x
    field int64 y
end

namedarray N
    field V v
    field V[2] vs
    field int64 k
    field int64[3] ks
end
)";

}  // namespace

TEST_CASE("ts: value types as the wasm package gives them (README Values)") {
    auto set = load({kValues});
    auto mod = to_typescript(*set.find_service("t.values"), set);
    const auto& d = mod.declarations;
    INFO(d);
    CHECK(mod.file_stem == "t.values");
    CHECK(has(d, "import type * as $rr from \"robotraconteur-wasm\";"));
    CHECK(has(d, "export interface S {"));
    CHECK(has(d, "  d: number;\n"));
    CHECK(has(d, "  i64: bigint;\n"));
    CHECK(has(d, "  u32: number;\n"));
    CHECK(has(d, "  b: boolean;\n"));
    CHECK(has(d, "  c: $rr.Complex;\n"));
    CHECK(has(d, "  s: string;\n"));
    CHECK(has(d, "  e: Color;\n"));
    CHECK(has(d, "  da: Float64Array;\n"));
    CHECK(has(d, "  ua: BigUint64Array;\n"));
    CHECK(has(d, "  ba: boolean[];\n"));
    CHECK(has(d, "  ca: $rr.Complex[];\n"));
    CHECK(has(d, "  md: $rr.MultiDimArray<Int16Array>;\n"));
    // structs, containers and varvalues may be null (the runtime gives null for them)
    CHECK(has(d, "  nested: S | null;\n"));
    CHECK(has(d, "  list: Array<S | null> | null;\n"));
    CHECK(has(d, "  by_int: Map<number, number> | null;\n"));
    CHECK(has(d, "  by_name: Record<string, string> | null;\n"));
    CHECK(has(d, "  any: $rr.VarValue | null;\n"));
    CHECK(has(d, "  one_pod: P;\n"));
    CHECK(has(d, "  pods: P[];\n"));
    CHECK(has(d, "  pod_md: $rr.MultiDimArray<P[]>;\n"));
    CHECK(has(d, "  na: N;\n"));
    CHECK(has(d, "  nas: N[];\n"));
    // pod fields: the general mapping; namedarray fields: items of the flat typed array (int64 → bigint)
    CHECK(has(d, "export interface P {\n  /** `field int8 a` */\n  a: number;\n  /** `field double[2] b` */\n  b: Float64Array;\n}"));
    CHECK(has(d, "export interface V {\n  /** `field int64 x` */\n  x: bigint;"));
    CHECK(has(d, "  v: V;\n"));
    CHECK(has(d, "  vs: V[];\n"));
    CHECK(has(d, "  k: bigint;\n"));
    CHECK(has(d, "  ks: BigInt64Array;\n"));
    // enums: a union of the numbers, and their names as a value
    CHECK(has(d, "export type Color = 0 | 1 | 16 | -5;"));
    CHECK(has(d, "  readonly blue: 16;\n"));
    // doc comments from `##` lines; `*/` cannot end the comment early
    CHECK(has(d, "/**\n * A color.\n *\n * Enum `t.values.Color`"));
    CHECK(has(d, " * whose comment has *\\/ in it.\n"));
    CHECK_FALSE(has_unknown_type(d));

    const auto& js = mod.javascript;
    INFO(js);
    CHECK(has(js, "export const Color = Object.freeze({ red: 0, green: 1, blue: 16, minus: -5 });"));
    CHECK(has(js, "export const greeting = \"hi \\\"there\\\"\";"));
    CHECK(has(js, "export const big = 0xFFFFFFFFFFFFFFFFn;"));
    CHECK(has(js, "export const small = Int32Array.of(1, 2, -3);"));
    CHECK(has(js, "export const S = Object.freeze({\n  NAME: \"s\",\n});"));
    CHECK(has(d, "export declare const big: bigint;"));
    CHECK(has(d, "export declare const greeting: \"hi \\\"there\\\"\";"));
}

TEST_CASE("ts: the .ts form holds the declarations and the enums and constants as values") {
    auto set = load({kValues});
    auto mod = to_typescript(*set.find_service("t.values"), set);
    const auto& src = mod.source;
    INFO(src);
    // the same interfaces and types as the .d.ts
    CHECK(has(src, "import type * as $rr from \"robotraconteur-wasm\";"));
    CHECK(has(src, "  i64: bigint;\n"));
    CHECK(has(src, "  list: Array<S | null> | null;\n"));
    CHECK(has(src, "export type Color = 0 | 1 | 16 | -5;"));
    // values, not ambient declarations: a build emits them (tsc with outDir, bundlers)
    CHECK_FALSE(has(src, "declare"));
    CHECK(has(src, "export const Color = Object.freeze({\n  red: 0,\n  green: 1,\n  blue: 16,\n  minus: -5,\n} as const);"));
    CHECK(has(src, "export const greeting: \"hi \\\"there\\\"\" = \"hi \\\"there\\\"\";"));
    CHECK(has(src, "export const big: bigint = 0xFFFFFFFFFFFFFFFFn;"));
    CHECK(has(src, "export const small: Int32Array = Int32Array.of(1, 2, -3);"));
    CHECK(has(src, "export const S = Object.freeze({\n"));
    CHECK(has(src, "  NAME: \"s\" as \"s\",\n});"));
    // the `##` doc comments too
    CHECK(has(src, "/**\n * A color.\n *\n * Enum `t.values.Color`"));
}

TEST_CASE("ts: the .ts form imports the package only when it uses it (noUnusedLocals builds)") {
    auto set = load({R"(service t.plain

stdver 0.10

enum Mode
    a = 1,
    b
end

struct Point
    field double x
end
)"});
    auto src = to_typescript(*set.find_service("t.plain"), set).source;
    INFO(src);
    CHECK_FALSE(has(src, "import"));
    CHECK(has(src, "export const Mode = Object.freeze({\n  a: 1,\n  b: 2,\n} as const);"));
    CHECK(has(src, "export interface Point {"));
}

TEST_CASE("ts: objects as interfaces of member proxies, by kind and direction") {
    auto set = load({R"(service t.obj

stdver 0.10

struct St
    field double x
end

object Child
    property int32 v
end

object O
    property St s
    property double ro [readonly]
    property double wo [writeonly]
    function St f(int32 a, string default)
    function void g()
    function int32{generator} gen(int32 n)
    function double{generator} sum(double{generator} xs)
    function void put(string{generator} items)
    event ev(int32 seq, St data)
    objref Child child
    objref Child{int32} by_int
    objref Child{string} by_name
    objref varobject any
    pipe St p
    pipe double[] p_ro [readonly]
    callback double cb(double x)
    wire St w
    wire St w_ro [readonly]
    wire int32 w_wo [writeonly]
    memory double[] m
    memory int32[*] m_md
    memory uint8[] m_ro [readonly]
end
)"});
    auto d = to_typescript(*set.find_service("t.obj"), set).declarations;
    INFO(d);
    CHECK(has(d, "export interface O extends $rr.ObjectBase {"));
    CHECK(has(d, "  s: $rr.Property<St | null>;\n"));
    CHECK(has(d, "  ro: $rr.ReadonlyProperty<number>;\n"));
    CHECK(has(d, "  wo: $rr.WriteonlyProperty<number>;\n"));
    CHECK(has(d, "  f(a: number, default_: string): Promise<St | null>;\n"));  // a reserved word as a parameter
    CHECK(has(d, "  g(): Promise<void>;\n"));
    CHECK(has(d, "  gen(n: number): Promise<$rr.Generator<number, undefined>>;\n"));
    CHECK(has(d, "  sum(): Promise<$rr.Generator<number, number>>;\n"));
    CHECK(has(d, "  put(): Promise<$rr.Generator<void, string>>;\n"));
    CHECK(has(d, "  ev: $rr.Event<[seq: number, data: St | null]>;\n"));
    CHECK(has(d, "  child: $rr.ObjRef<Child>;\n"));
    CHECK(has(d, "  by_int: $rr.IndexedObjRef<Child, number>;\n"));
    CHECK(has(d, "  by_name: $rr.IndexedObjRef<Child, string>;\n"));
    CHECK(has(d, "  any: $rr.ObjRef<$rr.ObjectProxy>;\n"));
    CHECK(has(d, "  p: $rr.Pipe<St | null>;\n"));
    CHECK(has(d, "  p_ro: $rr.ReadonlyPipe<Float64Array>;\n"));
    CHECK(has(d, "  cb: $rr.Callback<(x: number) => number>;\n"));
    CHECK(has(d, "  w: $rr.Wire<St | null>;\n"));
    CHECK(has(d, "  w_ro: $rr.ReadonlyWire<St | null>;\n"));
    CHECK(has(d, "  w_wo: $rr.WriteonlyWire<number>;\n"));
    CHECK(has(d, "  m: $rr.ArrayMemory<Float64Array>;\n"));
    CHECK(has(d, "  m_md: $rr.MultiDimMemory<Int32Array>;\n"));
    CHECK(has(d, "  m_ro: $rr.ReadonlyArrayMemory<Uint8Array>;\n"));
    // each member's robdef line as its doc comment
    CHECK(has(d, "  /** `function St f(int32 a, string default)` */\n"));
    CHECK(has(d, "  /** `property double ro [readonly]` */\n"));
}

TEST_CASE("ts: a member named then is typed through $member, never as a property (a proxy is no thenable)") {
    auto set = load({R"(service t.then

stdver 0.10

struct St
    field double then
end

object F
    function int32 then(int32 x)
    property double value
end

object P
    property St then
end
)"});
    auto d = to_typescript(*set.find_service("t.then"), set).declarations;
    INFO(d);
    CHECK(has(d, "export interface F extends $rr.ObjectBase {"));
    CHECK(has(d, "  $member(name: \"then\"): (x: number) => Promise<number>;\n"));
    CHECK(has(d, "  value: $rr.Property<number>;\n"));
    CHECK(has(d, "  $member(name: \"then\"): $rr.Property<St | null>;\n"));
    CHECK(has(d, "  $member(name: string): any;\n"));
    CHECK_FALSE(has(d, "  then("));
    CHECK_FALSE(has(d, "  then: $rr."));
    CHECK(has(d, "  then: number;\n"));  // a struct's field is a value, never called: it stays
}

TEST_CASE("ts: types of other definitions come from their modules (namespace imports)") {
    auto set = load({R"(service a.geo

stdver 0.10

struct Point
    field double x
end
)",
                     R"(service b.use

stdver 0.10

import a.geo

using a.geo.Point

struct Path
    field Point{list} points
    field a.geo.Point start
end
)"});
    auto use = to_typescript(*set.find_service("b.use"), set).declarations;
    INFO(use);
    CHECK(has(use, "import type * as a_geo from \"./a.geo.js\";\n"));
    CHECK(has(use, "  points: Array<a_geo.Point | null> | null;\n"));
    CHECK(has(use, "  start: a_geo.Point | null;\n"));
    auto geo = to_typescript(*set.find_service("a.geo"), set).declarations;
    CHECK_FALSE(has(geo, "import type * as a_"));
    CHECK(typescript_namespace_name("com.robotraconteur.geometry") == "com_robotraconteur_geometry");
}

TEST_CASE("ts: every standard definition generates without an unknown type", "[shared]") {
    auto dir = rr::robdef::test::shared_path("robdef-standard/group1");
    if (!dir) RR_SKIP("robdef-standard/group1 not found");
    ServiceDefinitionSet set;
    for (const auto& p : rr::robdef::test::robdef_files(*dir)) REQUIRE(set.add_text(rr::robdef::test::read_text(p), p.string()));
    REQUIRE_FALSE(has_errors(set.verify()));
    std::size_t n = 0;
    for (const auto* def : set.definitions()) {
        auto mod = to_typescript(*def, set);
        INFO(def->name);
        CHECK_FALSE(has_unknown_type(mod.declarations));
        ++n;
    }
    CHECK(n == 46);  // 45 and the built-in RobotRaconteurServiceIndex
    auto robot = to_typescript(*set.find_service("com.robotraconteur.robotics.robot"), set).declarations;
    CHECK(has(robot, "  robot_state: $rr.ReadonlyWire<RobotState | null>;\n"));
    CHECK(has(robot, "import type * as com_robotraconteur_geometry from \"./com.robotraconteur.geometry.js\";\n"));
}
