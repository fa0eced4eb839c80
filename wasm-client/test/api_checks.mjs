// API checks of the WebAssembly client against the interop test service
// (test/interop/robdef/experimental.interop_test.robdef; values: test/interop/interop_values.py).
// Runs unchanged in node (node_test.mjs) and in a browser (api.html). Uses only the public API.
//
//   const report = await runChecks(rr, url, { log });   // rr = the imported package
//   report = { passed: [names], failed: [{ name, error }] }

const UTF8_TEXT = 'Gr\u00fc\u00dfe, \u4e16\u754c! \u{1F916} "quoted" \\ tab\t newline\n end';
const F32_MAX = 3.4028234663852886e38;
const SVC = "experimental.interop_test";

// --- tiny assertion helpers (no node:assert in browsers) --------------------------------------------

class CheckFailed extends Error {}

function fmt(v) {
  if (typeof v === "bigint") return `${v}n`;
  if (ArrayBuffer.isView(v)) return `${v.constructor.name}[${Array.from(v, fmt).join(", ")}]`;
  if (Array.isArray(v)) return `[${v.map(fmt).join(", ")}]`;
  if (v instanceof Map) return `Map{${[...v].map(([k, x]) => `${fmt(k)} => ${fmt(x)}`).join(", ")}}`;
  if (v && typeof v === "object") return `{${Object.keys(v).map((k) => `${k}: ${fmt(v[k])}`).join(", ")}}`;
  if (Object.is(v, -0)) return "-0";
  return typeof v === "string" ? JSON.stringify(v) : String(v);
}

/** Deep equality: numbers by Object.is (so -0 ≠ 0 and NaN = NaN), typed arrays by type and items. */
export function deepEqual(a, b) {
  if (Object.is(a, b)) return true;
  if (ArrayBuffer.isView(a) || ArrayBuffer.isView(b)) {
    if (!ArrayBuffer.isView(a) || !ArrayBuffer.isView(b) || a.constructor !== b.constructor || a.length !== b.length)
      return false;
    for (let i = 0; i < a.length; i++) if (!Object.is(a[i], b[i])) return false;
    return true;
  }
  if (Array.isArray(a) || Array.isArray(b)) {
    if (!Array.isArray(a) || !Array.isArray(b) || a.length !== b.length) return false;
    return a.every((x, i) => deepEqual(x, b[i]));
  }
  if (a instanceof Map || b instanceof Map) {
    if (!(a instanceof Map) || !(b instanceof Map) || a.size !== b.size) return false;
    for (const [k, v] of a) if (!b.has(k) || !deepEqual(v, b.get(k))) return false;
    return true;
  }
  if (a && b && typeof a === "object" && typeof b === "object") {
    const ka = Object.keys(a).sort();
    const kb = Object.keys(b).sort();
    if (!deepEqual(ka, kb)) return false;
    return ka.every((k) => deepEqual(a[k], b[k]));
  }
  return false;
}

function eq(actual, expected, what) {
  if (!deepEqual(actual, expected)) throw new CheckFailed(`${what}: got ${fmt(actual)}, expected ${fmt(expected)}`);
}

function ok(cond, what) {
  if (!cond) throw new CheckFailed(what);
}

async function rejects(promiseOrFn, errorName, what) {
  try {
    await (typeof promiseOrFn === "function" ? promiseOrFn() : promiseOrFn);
  } catch (e) {
    if (!e || e.name !== "RRError") throw new CheckFailed(`${what}: threw a non-RRError ${e}`);
    if (errorName && e.errorName !== errorName)
      throw new CheckFailed(`${what}: errorName ${e.errorName} (${e.message}), expected ${errorName}`);
    return e;
  }
  throw new CheckFailed(`${what}: did not fail`);
}

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// A bound on a hang only: these checks run in ctest's crowded main phase.
async function until(cond, what, timeoutMs = 30000) {
  const end = Date.now() + timeoutMs;
  while (!cond()) {
    if (Date.now() > end) throw new CheckFailed(`timed out waiting for ${what}`);
    await sleep(10);
  }
}

const inner = (i, label = `inner ${i} \u00e9`, values = [i, i + 0.5, -i]) => ({
  id: i,
  label,
  values: Float64Array.from(values),
});

// --- the checks -------------------------------------------------------------------------------------

const CHECKS = [];
const check = (name, fn) => CHECKS.push({ name, fn });

check("connect: type, members, definitions, client", async ({ c }) => {
  eq(c.$type, `${SVC}.Root`, "$type");
  ok(c.$implements.includes(`${SVC}.Base`), "$implements has Base");
  const m = Object.fromEntries(c.$members.map((x) => [x.name, x]));
  eq(m.p_double.kind, "property", "p_double kind");
  eq(m.p_double.type, "double", "p_double type");
  eq(m.add.params, [{ name: "a", type: "int32" }, { name: "b", type: "int32" }], "add params");
  eq([m.count_up.generator, m.add.generator], [true, false], "generator flags");
  eq([m.ro_value.readonly, m.wo_value.writeonly, m.p_int32.readonly], [true, true, false], "direction flags");
  eq(m.child_by_int.index, "int32", "objref index kind");
  eq(m.mem_md.multidim, true, "multidim memory");
  const kinds = new Set(c.$members.map((x) => x.kind));
  for (const k of ["property", "function", "event", "objref", "pipe", "callback", "wire", "memory"])
    ok(kinds.has(k), `a member of kind ${k}`);
  ok(/service experimental\.interop_test/.test(c.$definitions[SVC]), "definition text");
  eq(c.$client.state, "connected", "state");
  ok(typeof c.$client.nodeId === "string" && c.$client.nodeId.length === 36, `nodeId ${c.$client.nodeId}`);
  await c.reset();
});

check("properties: decoded values of every kind", async ({ c }) => {
  eq(await c.p_double.get(), -1.7976931348623157e308, "p_double");
  eq(await c.p_single.get(), F32_MAX, "p_single");
  eq(await c.p_int8.get(), -128, "p_int8");
  eq(await c.p_uint32.get(), 4294967295, "p_uint32");
  eq(await c.p_int64.get(), -(2n ** 63n), "p_int64 (BigInt)");
  eq(await c.p_uint64.get(), 2n ** 64n - 1n, "p_uint64 (BigInt)");
  eq(await c.p_cdouble.get(), { real: 1.5, imag: -2.25 }, "p_cdouble");
  eq(await c.p_bool.get(), true, "p_bool");
  eq(await c.p_string.get(), UTF8_TEXT, "p_string (UTF-8)");
  eq(await c.p_enum.get(), 16, "p_enum");
  eq(
    await c.a_double.get(),
    Float64Array.from([0, -0, 1.5, Infinity, -Infinity, NaN, 5e-324, 1.7976931348623157e308]),
    "a_double",
  );
  eq(await c.a_int64.get(), BigInt64Array.from([-(2n ** 63n), -1n, 2n ** 63n - 1n]), "a_int64");
  eq(await c.a_uint64.get(), BigUint64Array.from([0n, 2n ** 64n - 1n, 2n ** 63n]), "a_uint64");
  eq((await c.a_uint8.get()).length, 256, "a_uint8 length");
  eq(await c.a_bool.get(), [true, false, false, true], "a_bool");
  eq(await c.a_cdouble.get(), [{ real: 1, imag: 2 }, { real: -0, imag: Infinity }], "a_cdouble");
  eq(await c.a_empty.get(), new Uint8Array(0), "a_empty");
  eq(await c.m_fixed.get(), { dims: [2, 3], array: Int32Array.from([-1, 2, -3, 4, -5, 6]) }, "m_fixed");
  eq(await c.m_bool.get(), { dims: [3, 2], array: [true, false, true, true, false, false] }, "m_bool");
  eq(await c.s_inner.get(), inner(1), "s_inner");
  eq(await c.s_null.get(), null, "s_null");
  const pod = await c.pod_scalar.get();
  eq(pod.x, 1.25, "pod.x");
  eq(pod.arr, Int32Array.from([0, 0, 2147483647, -2147483648]), "pod.arr");
  eq(pod.inners[1], { a: 100, b: Float64Array.from([1, 1, -1]) }, "pod.inners[1]");
  eq(pod.vec, { x: 1, y: -2, z: 0.125 }, "pod.vec (namedarray in pod)");
  eq(pod.c, { real: 0, imag: -0.75 }, "pod.c");
  eq(pod.md, { dims: [2, 2], array: Float64Array.from([1, 3, 2, 4]) }, "pod.md (column-major)");
  eq((await c.pod_array.get()).length, 3, "pod_array length");
  const podmd = await c.pod_md.get();
  eq([podmd.dims, podmd.array.length], [[3, 2], 6], "pod_md shape");
  eq(await c.na_scalar.get(), { x: 0.5, y: 0, z: 1e-300 }, "na_scalar");
  eq((await c.na_nested.get())[1], { position: { x: 1, y: 2, z: -1 }, orientation: Float64Array.from([1, 0, 0, 0.25]) }, "na_nested[1]");
  const mapInt = await c.map_int.get();
  ok(mapInt instanceof Map, "map_int is a Map");
  eq([...mapInt.keys()].sort((a, b) => a - b), [-2147483648, -1, 0, 2147483647], "map_int keys");
  eq(mapInt.get(2147483647), 5e-324, "map_int value");
  eq((await c.map_str.get())[""], "empty key", "map_str empty key");
  eq(await c.list_enum.get(), [0, 1, 16, -5], "list_enum");
  eq(await c.map_null.get(), null, "map_null");
  eq(await c.list_empty.get(), [], "list_empty");
  eq(await c.v_any.get(), { type: `${SVC}.Inner`, value: inner(3) }, "v_any");
  eq(await c.v_null.get(), null, "v_null");
  const vlist = await c.v_list.get();
  eq([vlist.length, vlist[0], vlist[2]], [4, { type: "string", value: UTF8_TEXT }, null], "v_list");
  eq((await c.v_map.get())["int32[*]"].type, "int32[*]", "v_map int32[*] type");
  eq(await c.ro_value.get(), 17, "ro_value");
  eq(await c.base_name.get(), "interop root", "base_name");
});

check("properties: every read/write property round-trips (the service checks what we encode)", async ({ c }) => {
  const props = c.$members.filter((m) => m.kind === "property" && !m.readonly && !m.writeonly);
  ok(props.length > 50, `${props.length} properties`);
  for (const m of props) {
    const v = await c[m.name].get();
    try {
      await c[m.name].set(v);
    } catch (e) {
      throw new CheckFailed(`${m.name} (${m.type}) set back: ${e.errorName}: ${e.message}`);
    }
  }
});

check("properties: second values from plain JS (numbers, BigInt, names, Map, null)", async ({ c }) => {
  const sets = [
    ["p_double", 5e-324],
    ["p_int64", 2n ** 63n - 1n],
    ["p_uint64", 0n],
    ["p_uint32", 0],
    ["p_cdouble", { real: -0, imag: 1e300 }],
    ["p_bool", false],
    ["p_string", ""],
    ["a_int32", Int32Array.from([9, 8])],
    ["a_int8", [5], Int8Array.from([5])],
    ["a_bool", [false]],
    ["a_cdouble", [{ real: 0, imag: 0 }]],
    ["a_bounded", new Int16Array(0)],
    ["m_double", { dims: [1, 1], array: Float64Array.from([9.5]) }],
    ["m_3d", { dims: [1, 2, 1], array: Uint8Array.from([7, 8]) }],
    ["s_null", inner(99)],
    ["na_array", []],
    ["na_md", { dims: [2, 1], array: [{ x: 0.5, y: 0, z: 1e-300 }, { x: 1.5, y: -1, z: 2e-300 }] }],
    ["map_null", new Map([[5, 5.5]])],
    ["map_str", { x: "" }],
    ["list_empty", ["now", "full"]],
    ["v_null", { type: "string", value: UTF8_TEXT }],
    ["v_any", { type: "int32[*]", value: { dims: [2, 2, 2], array: Int32Array.from([0, 1, 2, 3, 4, 5, 6, 7]) } }],
  ];
  for (const [name, v, expected = v] of sets) {
    try {
      await c[name].set(v);
    } catch (e) {
      throw new CheckFailed(`set ${name} = ${fmt(v)}: ${e.errorName}: ${e.message}`);
    }
    eq(await c[name].get(), expected, `${name} after set`);
  }
  await c.p_enum.set("minus");
  eq(await c.p_enum.get(), -5, "p_enum set by name");
  await c.reset();
  eq(await c.p_double.get(), -1.7976931348623157e308, "p_double after reset");
});

check("monitor lock: enter, use, exit", async ({ c }) => {
  await c.$monitorEnter(5000);
  eq(await c.ro_value.get(), 17, "read under the monitor lock");
  await c.$monitorExit();
});

check("properties: errors (service and local)", async ({ c }) => {
  await rejects(c.p_double.set(1.0), "RobotRaconteur.InvalidArgument", "service rejects a third value");
  await rejects(c.p_int8.set(1000), "RobotRaconteur.OutOfRange", "int8 out of range");
  await rejects(c.p_string.set(5), "RobotRaconteur.DataTypeMismatch", "number for string");
  await rejects(c.p_double.set(null), "RobotRaconteur.NullValue", "null for double");
  await rejects(c.a_fixed.set(Float64Array.from([1, 2])), "RobotRaconteur.DataTypeError", "double[3] with 2 items");
  await rejects(c.ro_value.set(1), "RobotRaconteur.ReadOnlyMember", "readonly set");
  await rejects(c.wo_value.get(), "RobotRaconteur.WriteOnlyMember", "writeonly get");
});

check("values: what JS cannot give exactly is refused before sending", async ({ c }) => {
  await rejects(c.p_int64.set(2 ** 60), "RobotRaconteur.OutOfRange", "number beyond 2^53 for int64");
  await rejects(c.p_uint64.set(-1n), "RobotRaconteur.OutOfRange", "negative BigInt for uint64");
  await rejects(c.p_int32.set(1.5), "RobotRaconteur.OutOfRange", "fraction for int32");
  await rejects(c.p_uint8.set(256), "RobotRaconteur.OutOfRange", "256 for uint8");
  await rejects(c.p_bool.set(1), "RobotRaconteur.DataTypeMismatch", "number for bool");
  await rejects(c.p_enum.set("purple"), "RobotRaconteur.InvalidArgument", "unknown enum name");
  await rejects(c.a_int16.set(["x"]), "RobotRaconteur.DataTypeMismatch", "string item in int16[]");
  await rejects(c.p_cdouble.set(1.5), "RobotRaconteur.DataTypeMismatch", "number for cdouble");
  await rejects(c.m_double.set({ dims: [2, 2], array: Float64Array.from([1]) }), "RobotRaconteur.DataTypeError",
    "dims product differs from the item count");
  await rejects(c.s_inner.set({ id: 1, label: "x" }), "RobotRaconteur.NullValue", "struct field missing");
  await rejects(c.map_int.set(new Map([["a", 1]])), "RobotRaconteur.OutOfRange", "non-numeric int32 map key");
  await rejects(c.v_any.set({ type: "no such type!", value: 1 }), "RobotRaconteur.DataTypeError", "bad varvalue type");
  eq(await c.p_int64.get(), -(2n ** 63n), "nothing was sent");
});

check("functions: results, parameters, errors", async ({ c }) => {
  eq(await c.add(2, 3), 5, "add");
  eq(await c.make_inner(4, "x", [1, 2]), inner(4, "x", [1, 2]), "make_inner");
  eq(await c.reset(), undefined, "void result");
  await c.wo_value.set(5);
  eq(await c.wo_value_last(), 5, "wo_value_last");
  await rejects(c.add(1), "RobotRaconteur.InvalidArgument", "argument count");
  const e = await rejects(c.throw_user("boom \u2713"), `${SVC}.InteropError`, "user exception");
  eq(e.message, "boom \u2713", "user exception message");
  await rejects(c.throw_standard(), "RobotRaconteur.InvalidArgument", "standard exception");
  const mix = await c.mix(2.5, "b", inner(1), (await c.pod_scalar.get()), { x: 1, y: 2, z: 3 },
    { type: "string", value: "any" }, 1, [3, 4]);
  eq([mix.f_double, mix.f_string, mix.f_enum, mix.f_strings], [2.5, "b", 1, ["3", "4"]], "mix result fields");
  eq(mix.f_vec, { x: 1, y: 2, z: 3 }, "mix namedarray parameter");
});

check("functions: every varvalue kind echoes back unchanged", async ({ c }) => {
  const kinds = ["double[]", "single[]", "int8[]", "uint8[]", "int16[]", "uint16[]", "int32[]", "uint32[]",
    "int64[]", "uint64[]", "cdouble[]", "csingle[]", "bool[]", "empty double[]", "double scalar", "string",
    "empty string", "double[*]", "int32[*]", "struct", "struct everything", "pod[]", "pod[*]", "namedarray[]",
    "namedarray[*]", "varvalue{list}", "varvalue{int32}", "varvalue{string}", "string{list}", "double{int32}",
    "nested", "null"];
  for (const k of kinds) {
    const v = await c.catalog(k);
    const back = await c.echo(v);
    eq(back, v, `echo(catalog(${k}))`);
  }
  eq((await c.catalog("int64[]")).value, BigInt64Array.from([-(2n ** 63n), 2n ** 63n - 1n]), "int64[] varvalue");
  eq((await c.catalog("pod[*]")).type, `${SVC}.TestPod[*]`, "pod[*] type");
  eq(await c.echo("plain"), { type: "string", value: "plain" }, "bare string as varvalue");
});

check("generators: iterate, next with parameter, close, abort", async ({ c }) => {
  const got = [];
  for await (const x of await c.count_up(3, 4)) got.push(x);
  eq(got, [3, 4, 5, 6], "count_up");
  const sum = await c.running_sum();
  eq(await sum.next(1), 1, "running_sum 1");
  eq(await sum.next(2.5), 3.5, "running_sum 2");
  await sum.close();
  const col = await c.collect();
  await col.next("a");
  await col.next("\u00fc");
  await col.close();
  eq(await c.collected.get(), ["a", "\u00fc"], "collect");
  const g = await c.count_up(0, 10);
  eq(await g.next(), 0, "first");
  await g.close();
  const h = await c.count_up(0, 10);
  await h.abort();
  const log = await c.generator_log();
  ok(log.includes("count_up:close") && log.includes("count_up:abort"), `generator_log ${fmt(log)}`);
  const end = await c.count_up(0, 1);
  await end.next();
  await rejects(end.next(), "RobotRaconteur.StopIteration", "after the last value");
});

check("events: subscribe, parameters, unsubscribe", async ({ c }) => {
  const got = [];
  let empty = 0;
  const off = c.ev_values.on((seq, text, data) => got.push({ seq, text, data }));
  const offEmpty = c.ev_empty.on(() => empty++);
  await c.fire_events(3);
  await until(() => got.length === 3 && empty === 1, "3 events and ev_empty");
  eq(got.map((e) => e.seq), [0, 1, 2], "seq");
  eq(got[1].text, "event 1 \u2713", "text");
  eq(got[2].data, inner(2, "event", [3]), "data");
  off();
  offEmpty();
  // a listener still on gets the same pushes: once it has them, the removed ones would have had them too
  const fence = [];
  const offFence = c.ev_values.on((e) => fence.push(e));
  await c.fire_events(2);
  await until(() => fence.length === 2, "2 events on the listener still on");
  offFence();
  eq([got.length, empty], [3, 1], "nothing after unsubscribing");
});

check("objrefs: plain, int32 and string index, nested, varobject", async ({ c }) => {
  const child = await c.child.get();
  eq(child.$type, `${SVC}.Child`, "child type");
  ok(/object Child/.test(child.$definitions[SVC]), "child $definitions");
  eq(typeof (await child.name.get()), "string", "child name");
  const byInt = await c.child_by_int.get(7);
  eq(await byInt.name.get(), "child[7]", "child_by_int[7]");
  const neg = await c.child_by_int.get(-1);
  eq(await neg.name.get(), "child[-1]", "child_by_int[-1]");
  const byName = await c.child_by_name.get("with space_and-dash");
  eq(await byName.name.get(), "child[with space_and-dash]", "child_by_name");
  await byInt.value.set(41);
  eq(await byInt.value.get(), 41, "child property set");
  ok(typeof (await byInt.describe()) === "string", "child function");
  const leaf = await child.leaf.get();
  eq(leaf.$type, `${SVC}.Leaf`, "leaf type");
  eq(typeof (await leaf.scaled(2)), "number", "leaf function");
  const any = await c.any_obj.get();
  eq(any.$type, `${SVC}.Leaf`, "varobject type");
  await rejects(c.child_by_int.get(3), null, "unknown index");
  await c.reset();
});

check("pipes: echo, service stream with onPacket and iteration, closed by the service", async ({ c }) => {
  const p = await c.p_echo.connect();
  ok(Number.isInteger(p.index), "index");
  const n = await p.send(inner(5));
  eq(n, 1, "first packet number");
  eq(await p.receive(), inner(5), "echoed packet");
  await p.close();

  const s = await c.p_stream.connect();
  const got = [];
  const off = s.onPacket((x) => got.push(x));
  await c.send_stream(3);
  await until(() => got.length === 3, "3 stream packets");
  eq(got, [Float64Array.from([0, 0]), Float64Array.from([1, 0.5]), Float64Array.from([2, 1])], "stream packets");
  off();
  await c.send_stream(2);
  const iter = [];
  for await (const x of s) {
    iter.push(x);
    if (iter.length === 2) break;
  }
  eq(iter[1], Float64Array.from([1, 0.5]), "iterated packet");
  ok(s.closed, "break closes the endpoint");

  const s3 = await c.p_stream.connect();
  await c.send_stream(2);
  // the endpoint's own queue (no public count): the packets are there before a listener is added
  await until(() => s3.queue.items.length === 2, "2 packets queued on an endpoint without listeners");
  const late = [];
  s3.onPacket((x) => late.push(x));
  await until(() => late.length === 2, "packets queued before onPacket reach it");
  await s3.close();

  const s2 = await c.p_stream.connect();
  let closedBy = null;
  s2.onClose((e) => (closedBy = e ?? "closed"));
  await c.close_stream();
  await until(() => closedBy !== null, "PipeClosed");
  await rejects(s2.send(Float64Array.from([1])), null, "send on a closed endpoint");

  const u = await c.p_unreliable.connect();
  await u.send("\u00e9cho");
  eq(await u.receive(), "\u00e9cho", "unreliable echo");
  await u.close();
});

check("callbacks: async handler result, parameters, errors back to the service", async ({ c }) => {
  let notified = null;
  c.cb_notify.set((info) => {
    notified = info;
  });
  c.cb_compute.set(async (x, label) => {
    await sleep(5);
    return x * 2 + label.length;
  });
  eq(await c.call_callbacks(1.5), 1.5 * 2 + "\u03bb-label".length + 1, "call_callbacks result");
  ok(notified && typeof notified.id === "number" && ArrayBuffer.isView(notified.values), `cb_notify got ${fmt(notified)}`);
  c.cb_compute.set(() => {
    throw new Error("client says no");
  });
  await rejects(c.call_callbacks(1), null, "a failing callback fails the call");
  c.cb_compute.set(null);
  c.cb_notify.set(null);
});

check("wires: InValue, time stamps, onChange, OutValue, lifespan, peek/poke, writeonly", async ({ c }) => {
  const w = await c.w_state.connect();
  const v = await w.waitInValue(30000);
  ok(typeof v.id === "number" && (v.label === "tick" || v.label === "demand"), `w_state value ${fmt(v)}`);
  ok(w.inValueTime.seconds > 1.6e9, `time stamp ${fmt(w.inValueTime)}`);
  const seen = [];
  const off = w.onChange((x, ts) => seen.push([x, ts]));
  await c.update_state(42);
  await until(() => seen.some(([x]) => x.id === 42 && x.label === "demand"), "demand value 42");
  off();
  ok(typeof seen[0][1].nanoseconds === "number", "onChange time stamp");
  let ro = null;
  try {
    w.outValue = inner(1);
  } catch (e) {
    ro = e;
  }
  eq(ro?.errorName, "RobotRaconteur.ReadOnlyMember", "OutValue of a readonly wire");
  eq((await c.w_state.peekInValue()).label !== undefined, true, "peekInValue");
  await w.close();

  const b = await c.w_both.connect();
  b.outValue = Float64Array.from([1, 2, 3]);
  eq(b.outValue, Float64Array.from([1, 2, 3]), "OutValue");
  await until(() => b.inValueValid && deepEqual(b.inValue, Float64Array.from([3, 2, 1])), "reversed echo");
  b.lifespanMs = 100;
  eq(b.lifespanMs, 100, "lifespanMs");
  await sleep(300);
  let expired = null;
  try {
    void b.inValue;
  } catch (e) {
    expired = e;
  }
  eq(expired?.errorName, "RobotRaconteur.ValueNotSet", "InValue older than the lifespan");
  await b.close();
  await c.w_both.pokeOutValue(Float64Array.from([5, 6]));
  ok(ArrayBuffer.isView(await c.w_both.peekOutValue()), "peekOutValue");

  const sink = await c.w_sink.connect();
  sink.outValue = 77;
  let last = -1;
  for (const end = Date.now() + 30000; last !== 77 && Date.now() < end;) {
    last = await c.w_sink_value();
    if (last !== 77) await sleep(20);
  }
  eq(last, 77, "w_sink received");
  await sink.close();
});

check("memories: 1-D, multi-dim, pod, namedarray, readonly", async ({ c }) => {
  eq(await c.mem_double.length(), 100, "mem_double length");
  eq(await c.mem_double.read(0, 5), Float64Array.from([0, 0.5, 1, 1.5, 2]), "mem_double read");
  await c.mem_double.write(10, Float64Array.from([7, 8]));
  eq(await c.mem_double.read(9, 3), Float64Array.from([4.5, 7, 8]), "mem_double after write");
  eq(await c.mem_md.dimensions(), [4, 5], "mem_md dimensions");
  eq(await c.mem_md.read([0, 0], [2, 2]), { dims: [2, 2], array: Int32Array.from([-10, -9, -6, -5]) }, "mem_md read");
  await c.mem_md.write([1, 1], { dims: [1, 2], array: Int32Array.from([99, 98]) });
  eq(await c.mem_md.read([1, 1], [1, 2]), { dims: [1, 2], array: Int32Array.from([99, 98]) }, "mem_md after write");
  const pods = await c.mem_pod.read(0, 2);
  eq([pods.length, pods[0].x], [2, 1.25 * 31], "mem_pod read");
  await c.mem_pod.write(1, [pods[0]]);
  eq((await c.mem_pod.read(1, 1))[0], pods[0], "mem_pod after write");
  eq(await c.mem_na.read(0, 1), [{ x: 50.5, y: -50, z: 1e-300 * 51 }], "mem_na read");
  const namd = await c.mem_na_md.read([0, 0], [3, 2]);
  eq([namd.dims, namd.array.length, namd.array[0].x], [[3, 2], 6, 60.5], "mem_na_md read");
  const podmd = await c.mem_pod_md.read([0, 0], [2, 3]);
  eq([podmd.dims, podmd.array.length], [[2, 3], 6], "mem_pod_md read");
  eq((await c.mem_ro.read(0, 4)), Uint8Array.from([0, 3, 6, 9]), "mem_ro read");
  await rejects(c.mem_ro.write(0, Uint8Array.from([1])), "RobotRaconteur.ReadOnlyMember", "readonly memory write");
  await c.reset();
});

/** Runs every check against `url`; the last one closes the connection. */
export async function runChecks(rr, url, { log = () => {}, only = null, timeoutMs = 15000, options = {} } = {}) {
  const report = { passed: [], failed: [] };
  let c;
  try {
    c = await rr.connect(url, { timeoutMs, ...options });
  } catch (e) {
    report.failed.push({ name: "connect", error: `${e.errorName ?? ""} ${e.message}` });
    return report;
  }
  for (const { name, fn } of CHECKS) {
    if (only && !only.test(name)) continue;
    const t0 = Date.now();
    try {
      await fn({ c, rr });
      report.passed.push(name);
      log(`ok   ${name} (${Date.now() - t0} ms)`);
    } catch (e) {
      const error = e instanceof CheckFailed ? e.message : `${e?.errorName ?? ""} ${e?.message ?? e}`;
      report.failed.push({ name, error });
      log(`FAIL ${name}: ${error}`);
    }
  }
  // close: the client reports it, and further calls fail with ConnectionError
  try {
    let closed = null;
    c.$client.onClose((e) => (closed = e));
    await c.$client.close();
    await until(() => closed !== null, "onClose");
    eq(c.$client.state, "closed", "state after close");
    await rejects(c.add(1, 2), "RobotRaconteur.ConnectionError", "call after close");
    report.passed.push("close");
    log("ok   close");
  } catch (e) {
    report.failed.push({ name: "close", error: e.message });
    log(`FAIL close: ${e.message}`);
  }
  return report;
}
