// Typed use of the interop test service (test/interop/robdef/experimental.interop_test.robdef; types from
// `rr-robdef ts` in gen/interop): every value type the service serves, checked at run time to be what
// its declared type says, and the member kinds the demo devices lack (generators, indexed objrefs,
// varobject, readonly/writeonly wires, multi-dim and pod memories, events with parameters).
// `node interop.js rr+ws://HOST:PORT/?service=interop`.
import WebSocket from "ws";
import { connect, type VarValue, type Complex, type MultiDimArray } from "robotraconteur-wasm";
import type { Root, Child, Everything, Inner, TestPod, Vec3, Pose } from "./gen/interop/experimental.interop_test.js";
import { Color, answer, big, gains } from "./gen/interop/experimental.interop_test.js";

function check(ok: boolean, what: string): void {
  if (!ok) throw new Error(`typed interop: ${what}`);
  console.log(`ok: ${what}`);
}
// Each takes exactly the declared type; the body checks the value really is that at run time.
const num = (x: number, w: string) => check(typeof x === "number", `${w}: number`);
const big64 = (x: bigint, w: string) => check(typeof x === "bigint", `${w}: bigint`);
const bool = (x: boolean, w: string) => check(typeof x === "boolean", `${w}: boolean`);
const str = (x: string, w: string) => check(typeof x === "string", `${w}: string`);
const cplx = (x: Complex, w: string) => check(typeof x.real === "number" && typeof x.imag === "number", `${w}: Complex`);
const typed = <A extends ArrayBufferView>(ctor: new (n: number) => A) => (x: A, w: string) =>
  check(x instanceof ctor, `${w}: ${ctor.name}`);
const md = <A>(inner: (a: A, w: string) => void) => (x: MultiDimArray<A>, w: string) => {
  check(Array.isArray(x.dims) && x.dims.every((d) => typeof d === "number"), `${w}: {dims}`);
  inner(x.array, `${w}.array`);
};
const vec3 = (x: Vec3, w: string) => { num(x.x, `${w}.x`); num(x.y, `${w}.y`); num(x.z, `${w}.z`); };
const inner = (x: Inner, w: string) => { num(x.id, `${w}.id`); str(x.label, `${w}.label`); typed(Float64Array)(x.values, `${w}.values`); };
const pod = (x: TestPod, w: string) => {
  num(x.x, `${w}.x`);
  typed(Int32Array)(x.arr, `${w}.arr`);
  typed(Uint8Array)(x.bounded, `${w}.bounded`);
  num(x.inner.a, `${w}.inner.a`);
  typed(Float64Array)(x.inner.b, `${w}.inner.b`);
  check(Array.isArray(x.inners) && x.inners.length === 2, `${w}.inners: PodInner[]`);
  vec3(x.vec, `${w}.vec`);
  cplx(x.c, `${w}.c`);
  md(typed(Float64Array))(x.md, `${w}.md`);
};
const varvalue = (x: VarValue | null, w: string) => check(x === null || (typeof x.type === "string" && "value" in x), `${w}: VarValue | null`);

async function main(url: string): Promise<void> {
  const root = await connect<Root>(url, { WebSocket });
  await root.reset();
  num(await root.p_double.get(), "p_double");
  num(await root.p_uint32.get(), "p_uint32");
  big64(await root.p_int64.get(), "p_int64");
  big64(await root.p_uint64.get(), "p_uint64");
  cplx(await root.p_csingle.get(), "p_csingle");
  bool(await root.p_bool.get(), "p_bool");
  str(await root.p_string.get(), "p_string");
  const c: Color = await root.p_enum.get();
  check(Object.values(Color).includes(c), `p_enum ${c} is a Color value`);
  typed(Float64Array)(await root.a_double.get(), "a_double");
  typed(BigUint64Array)(await root.a_uint64.get(), "a_uint64");
  typed(Int16Array)(await root.a_bounded.get(), "a_bounded");
  const ab: boolean[] = await root.a_bool.get();
  check(Array.isArray(ab) && ab.every((b) => typeof b === "boolean"), "a_bool: boolean[]");
  const ac: Complex[] = await root.a_cdouble.get();
  check(Array.isArray(ac) && ac.every((x) => typeof x.real === "number"), "a_cdouble: Complex[]");
  md(typed(Int32Array))(await root.m_fixed.get(), "m_fixed");
  md((a: Complex[], w: string) => check(Array.isArray(a), `${w}: Complex[]`))(await root.m_complex.get(), "m_complex");
  md((a: boolean[], w: string) => check(Array.isArray(a) && typeof a[0] === "boolean", `${w}: boolean[]`))(await root.m_bool.get(), "m_bool");

  // structs may be null: s_null's first value is null
  const nothing: Inner | null = await root.s_null.get();
  check(nothing === null, "s_null: null (the type says Inner | null)");
  const e: Everything | null = await root.s_everything.get();
  check(e !== null, "s_everything");
  if (e) {
    big64(e.f_uint64, "Everything.f_uint64");
    num(e.f_int8, "Everything.f_int8");
    cplx(e.f_cdouble, "Everything.f_cdouble");
    bool(e.f_bool, "Everything.f_bool");
    num(e.f_enum, "Everything.f_enum");
    typed(Float64Array)(e.f_fixed, "Everything.f_fixed");
    md(typed(Float64Array))(e.f_md, "Everything.f_md");
    if (e.f_inner) inner(e.f_inner, "Everything.f_inner");
    check(e.f_inner_null === null || typeof e.f_inner_null === "object", "Everything.f_inner_null: Inner | null");
    check(e.f_inner_list === null || Array.isArray(e.f_inner_list), "Everything.f_inner_list: Array | null");
    check(e.f_inner_by_int === null || e.f_inner_by_int instanceof Map, "Everything.f_inner_by_int: Map | null");
    check(e.f_inner_by_name === null || (typeof e.f_inner_by_name === "object" && !(e.f_inner_by_name instanceof Map)), "Everything.f_inner_by_name: Record | null");
    pod(e.f_pod, "Everything.f_pod");
    vec3(e.f_vec, "Everything.f_vec");
    check(Array.isArray(e.f_vecs), "Everything.f_vecs: Vec3[]");
    varvalue(e.f_any, "Everything.f_any");
    check(e.f_any_null === null, "Everything.f_any_null: null");
  }
  pod(await root.pod_scalar.get(), "pod_scalar");
  const pods: TestPod[] = await root.pod_array.get();
  pods.forEach((p, i) => pod(p, `pod_array[${i}]`));
  const podmd = await root.pod_md.get();
  check(Array.isArray(podmd.array) && podmd.dims.length === 2, "pod_md: MultiDimArray<TestPod[]>");
  vec3(await root.na_scalar.get(), "na_scalar");
  const poses: Pose[] = await root.na_nested.get();
  poses.forEach((p, i) => { vec3(p.position, `na_nested[${i}].position`); typed(Float64Array)(p.orientation, `na_nested[${i}].orientation`); });
  const mi = await root.map_int.get();
  check(mi instanceof Map && [...mi.values()].every((v) => typeof v === "number"), "map_int: Map<number, number>");
  check((await root.map_null.get()) === null, "map_null: null (the type says Map | null)");
  const ms = await root.map_str.get();
  check(ms !== null && Object.values(ms).every((v) => typeof v === "string"), "map_str: Record<string, string>");
  const la = await root.list_arrays.get();
  check(la !== null && la.every((a) => a instanceof Float64Array), "list_arrays: Array<Float64Array>");
  const va = await root.v_any.get();
  varvalue(va, "v_any");
  const vm = await root.v_map.get();
  check(vm !== null && Object.values(vm).every((v) => v === null || typeof v.type === "string"), "v_map: Record<string, VarValue | null>");
  const echoed = await root.echo({ type: "int32[]", value: Int32Array.of(1, 2) });
  check(echoed !== null && echoed.type === "int32[]" && echoed.value instanceof Int32Array, "echo varvalue int32[] narrows on type");
  num(await root.ro_value.get(), "ro_value [readonly]");
  await root.wo_value.set(7);
  check((await root.wo_value_last()) === 7, "wo_value [writeonly] set");
  check((await root.add(2, 3)) === 5, "function add");

  // generators
  const g = await root.count_up(3, 3);
  const got: number[] = [];
  for await (const x of g) got.push(x);
  check(got.join() === "3,4,5", `generator count_up: ${got}`);
  const rs = await root.running_sum();
  const s1: number = await rs.next(1.5);
  const s2: number = await rs.next(2);
  await rs.close();
  check(s1 === 1.5 && s2 === 3.5, "generator running_sum(double{generator})");

  // events with parameters
  const seen: string[] = [];
  const off = root.ev_values.on((seq: number, text: string, data: Inner | null) => seen.push(`${seq}:${text}:${data?.id}`));
  await root.fire_events(2);
  // wait for the pushes (bounded against a hang only: this runs beside a crowded CI phase)
  for (const end = Date.now() + 30000; seen.length < 2 && Date.now() < end;) await new Promise((r) => setTimeout(r, 20));
  off();
  check(seen.length === 2, `event ev_values(seq, text, data): ${seen}`);

  // objrefs: plain, indexed, varobject
  const child: Child = await root.child.get();
  str(await child.describe(), "objref child → Child.describe()");
  const byInt: Child = await root.child_by_int.get(7);
  const byName: Child = await root.child_by_name.get("alpha");
  check(byInt.$type.endsWith(".Child") && byName.$type.endsWith(".Child"), "indexed objrefs (int32, string)");
  const leaf = await child.leaf.get();
  num(await leaf.scaled(2), "objref leaf → Leaf.scaled");
  const anyObj = await root.any_obj.get();
  check(anyObj.$type.endsWith(".Leaf"), `objref varobject → ObjectProxy (${anyObj.$type})`);

  // pipes
  const ep = await root.p_stream.connect();
  await root.send_stream(2);
  const packet = await ep.receive();
  check(packet instanceof Float64Array, "readonly pipe p_stream: Float64Array packets");
  await ep.close();
  const echoEp = await root.p_echo.connect();
  await echoEp.send({ id: 1, label: "x", values: Float64Array.of(1) });
  const back = await echoEp.receive();
  check(back != null && back.id === 1, "pipe p_echo: Inner back");
  await echoEp.close();

  // callbacks
  root.cb_compute.set((x: number, label: string) => x * 2 + label.length * 0);
  root.cb_notify.set((info: Inner | null) => { void info; });
  num(await root.call_callbacks(2), "callbacks cb_compute/cb_notify via call_callbacks");
  root.cb_compute.set(null);

  // wires: readonly, both ways, writeonly
  const ws = await root.w_state.connect();
  const st = await ws.waitInValue(5000);
  check(st !== null && typeof st.label === "string", "readonly wire w_state: Inner InValue");
  await ws.close();
  const wb = await root.w_both.connect();
  wb.outValue = Float64Array.of(1, 2, 3);
  const rev = await wb.waitInValue(5000);
  check(rev instanceof Float64Array, "wire w_both: Float64Array both ways");
  await wb.close();
  await root.w_sink.pokeOutValue(11);
  check((await root.w_sink_value()) === 11, "writeonly wire w_sink: pokeOutValue");

  // memories
  typed(Float64Array)(await root.mem_double.read(0, 4), "memory mem_double");
  md(typed(Int32Array))(await root.mem_md.read([0, 0], [2, 2]), "memory mem_md (int32[*])");
  const mp: TestPod[] = await root.mem_pod.read(0, 2);
  mp.forEach((p, i) => pod(p, `memory mem_pod[${i}]`));
  const mna: Vec3[] = await root.mem_na.read(0, 2);
  mna.forEach((v, i) => vec3(v, `memory mem_na[${i}]`));
  typed(Uint8Array)(await root.mem_ro.read(0, 2), "memory mem_ro [readonly]");

  // the generated .js: enum and constant values
  check(Color.blue === 16 && answer === 42 && big === 0xFFFFFFFFFFFFFFFFn && gains instanceof Float64Array, "enum and constants from the generated .js");
  await root.reset();
  await root.$client.close();
}

main(process.argv[2] ?? "rr+ws://127.0.0.1:8080/?service=interop").then(
  () => console.log("typed interop: all ok"),
  (e: unknown) => {
    console.error(e);
    process.exit(1);
  });
