// Editor text <-> values typed by robdef (src/value_codec.js, src/std/rr_types.js).
import { test } from "node:test";
import assert from "node:assert/strict";
import { parseType, parseNumber, isPlottable } from "../src/std/rr_types.js";
import { parseInput, editorText } from "../src/value_codec.js";
import { formatValue, toPlain } from "../src/std/value_text.js";
import { TypeDescriber } from "../src/std/describe.js";
import { RobdefOutline } from "../src/std/robdef_outline.js";

const outline = new RobdefOutline({
  "experimental.t": `service experimental.t
stdver 0.10
enum Mode
    off = 0, slow = 2,
    fast
end
struct Point
    field double x
    field int64 id
    field uint8[] raw
end
object T
    property Point p
end
`,
});

// the descriptors the page makes once per member (std/describe.js), as the editors get them
const types = new TypeDescriber(outline);
const typed = (text) => types.describe(text, "experimental.t");

test("type texts split into base, array and container", () => {
  assert.deepEqual(parseType("double[]"), { text: "double[]", base: "double", array: "vector", dims: null, container: null });
  assert.deepEqual(parseType("uint8[*]").array, "multidim");
  assert.deepEqual(parseType("int32[2,3]"), { text: "int32[2,3]", base: "int32", array: "multidim", dims: [2, 3], container: null });
  assert.deepEqual(parseType("string{int32}"), { text: "string{int32}", base: "string", array: null, dims: null, container: "int32" });
  assert.equal(parseType("double[3]{list}").container, "list");
  assert.equal(parseType("double[3]{list}").array, "vector");
  assert.ok(isPlottable("int32") && isPlottable("double[]") && !isPlottable("uint8[*]") && !isPlottable("Point"));
});

test("numbers are checked against their type", () => {
  assert.equal(parseNumber("int16", "-32768"), -32768);
  assert.throws(() => parseNumber("int16", "32768"), /out of range for int16/);
  assert.throws(() => parseNumber("uint8", "1.5"), /not an integer/);
  assert.throws(() => parseNumber("double", "abc"), /not a number/);
  assert.equal(parseNumber("int64", "-9007199254740993"), -9007199254740993n);
  assert.throws(() => parseNumber("uint64", "-1"), /negative/);
  assert.equal(parseNumber("bool", "true"), true);
});

test("plain text gives scalars and typed arrays", () => {
  const v = parseInput(typed("double[]"), "0.2, 0.4 0.6");
  assert.ok(v instanceof Float64Array);
  assert.deepEqual(Array.from(v), [0.2, 0.4, 0.6]);
  assert.ok(parseInput(typed("int64[]"), "1,2") instanceof BigInt64Array);
  assert.equal(parseInput(typed("string"), "  spaced  "), "  spaced  ");
  assert.equal(parseInput(typed("Mode"), "fast"), 3);
  assert.equal(parseInput(typed("Mode"), "2"), 2);
  assert.throws(() => parseInput(typed("uint8[]"), "1, 300"), /out of range/);
});

test("JSON gives structs typed field by field", () => {
  const p = parseInput(typed("Point"), '{"x": 1.5, "id": "12345678901234567", "raw": [1, 2]}');
  assert.equal(p.x, 1.5);
  assert.equal(p.id, 12345678901234567n);
  assert.ok(p.raw instanceof Uint8Array);
  assert.throws(() => parseInput(typed("Point"), '{"x": 1}'), /field id missing/);
  const list = parseInput(typed("Point{list}"), '[{"x": 0, "id": 1, "raw": []}]');
  assert.equal(list.length, 1);
  const map = parseInput(typed("double{int32}"), '{"3": 1.5}');
  assert.ok(map instanceof Map && map.get(3) === 1.5);
  const md = parseInput(typed("uint8[*]"), '{"dims": [2, 1], "array": [7, 8]}');
  assert.deepEqual([Array.from(md.dims), Array.from(md.array)], [[2, 1], [7, 8]]);
});

test("values format for display and back for editors", () => {
  assert.equal(formatValue(Float64Array.of(0.2, 0.4, 0.6)), "[0.2, 0.4, 0.6]");
  assert.equal(formatValue(new Uint8Array(40), 4), "[0, 0, 0, 0, … 36 more]");
  assert.equal(formatValue({ a: 1n, b: "x" }), '{a: 1, b: "x"}');
  assert.equal(formatValue(new Map([[0, "Left"]])), '{0: "Left"}');
  assert.equal(formatValue({ dims: Uint32Array.of(2, 2), array: Uint8Array.of(1, 2, 3, 4) }), "2×2 [1, 2, 3, 4]");
  assert.equal(editorText(typed("double[]"), Float64Array.of(1, 2.5)), "1, 2.5");
  assert.equal(editorText(typed("Point"), { x: 1, id: 2n, raw: Uint8Array.of(3) }), '{"x":1,"id":"2","raw":[3]}');
  assert.deepEqual(toPlain(new Map([[1, BigInt64Array.of(5n)]])), { 1: ["5"] });
});

test("numbers JSON cannot hold, nulls, complex numbers and varvalues survive an editor round trip", () => {
  const a = Float64Array.of(0, -0, Infinity, -Infinity, NaN, 5e-324);
  const text = editorText(typed("double[]"), a);
  assert.equal(text, "0, -0, Infinity, -Infinity, NaN, 5e-324");
  const back = parseInput(typed("double[]"), text);
  assert.ok(Object.is(back[1], -0) && Number.isNaN(back[4]) && back[5] === 5e-324);
  const map = new Map([[-1, -0], [0, NaN]]);
  const m = parseInput(typed("double{int32}"), editorText(typed("double{int32}"), map));
  assert.ok(Object.is(m.get(-1), -0) && Number.isNaN(m.get(0)));
  assert.equal(editorText(typed("Point"), null), "null");
  assert.equal(parseInput(typed("Point"), "null"), null);
  assert.equal(editorText(typed("string"), "two\nlines"), "two\nlines");
  const c = parseInput(typed("cdouble[]"), editorText(typed("cdouble[]"), [{ real: -0, imag: Infinity }]));
  assert.ok(Object.is(c[0].real, -0) && c[0].imag === Infinity);
  const v = { type: "experimental.t.Point[]", value: [{ x: NaN, id: 9007199254740993n, raw: Uint8Array.of(1) }] };
  const vb = parseInput(typed("varvalue"), editorText(typed("varvalue"), v));
  assert.equal(vb.type, "experimental.t.Point[]");
  assert.ok(Number.isNaN(vb.value[0].x) && vb.value[0].id === 9007199254740993n && vb.value[0].raw instanceof Uint8Array);
  assert.equal(formatValue(new Map([[5, "b"], [-1, "a"]])), '{-1: "a", 5: "b"}');
  assert.equal(formatValue(-0), "-0");
});
