// Editor text -> values for the client package, typed by a type descriptor (std/describe.js, made
// once per member when the device's definitions arrive): typed arrays for numeric arrays, BigInt for
// int64, plain objects for structs, {dims, array} for multidim arrays, {real, imag} for complex
// numbers, {type, value} for varvalues; and values -> editor text. Structured inputs are JSON
// (JSON.parse); numbers JSON cannot hold are written as strings there ("NaN", "Infinity",
// "-Infinity", "-0"), as are 64-bit integers. Nothing here reads type text: the descriptor carries
// the shape, and a varvalue's own type is described by the describer that made its descriptor.

import { NUMERIC_ARRAYS, parseNumber, isNumericBase } from "./std/rr_types.js";
import { numberText, toPlain } from "./std/value_text.js";

const scalar = (d) => !d.container && !d.array;

/**
 * Converts editor text to a value of the type described by `d`. Numbers and numeric vectors are
 * plain text ("1.5", "0.2, 0.4, 0.6"); strings are taken as written; enums by name or number;
 * everything else is JSON, converted field by field with the descriptor's fields. Throws Error with
 * the reason.
 */
export function parseInput(d, text) {
  if (scalar(d)) {
    if (isNumericBase(d.base)) return parseNumber(d.base, text);
    if (d.base === "string") return String(text);
    if (d.kind === "enum") return parseEnum(d.enumValues, text);
  }
  if (!d.container && d.array === "vector" && isNumericBase(d.base) && !String(text).trim().startsWith("[")) {
    const parts = String(text).split(/[\s,;]+/).filter((p) => p !== "");
    return toArray(d.base, parts.map((p) => parseNumber(d.base, p)));
  }
  let json;
  try { json = JSON.parse(text); } catch (e) { throw new Error(`JSON expected for ${d.text}: ${e.message}`); }
  return fromJson(d, json);
}

function parseEnum(values, text) {
  const s = String(text).trim();
  const named = values.find((v) => v.name === s);
  if (named) return named.value;
  const n = Number(s);
  if (Number.isInteger(n)) return n;
  throw new Error(`not a value of the enum: ${s}`);
}

function toArray(base, items) {
  const Ctor = NUMERIC_ARRAYS[base];
  if (!Ctor) return items.map(Boolean);
  if (Ctor === BigInt64Array || Ctor === BigUint64Array) return Ctor.from(items.map((x) => BigInt(x)));
  return Ctor.from(items);
}

/** The items of an array of descriptor `d` (vector or multidim): a typed array for numbers, else each item converted. */
function arrayFrom(d, items) {
  if (isNumericBase(d.base)) return toArray(d.base, items.map((x) => parseNumber(d.base, String(x))));
  return items.map((x) => fromJson(d.element, x));
}

/** Converts parsed JSON to a value of the type described by `d` (see parseInput). */
export function fromJson(d, json) {
  if (json === null && (d.container || d.array || !isNumericBase(d.base))) return null;
  if (d.container) {
    if (d.container === "list") return asList(json).map((x) => fromJson(d.element, x));
    const out = d.container === "int32" ? new Map() : {};
    for (const [k, v] of Object.entries(json)) {
      const item = fromJson(d.element, v);
      if (out instanceof Map) out.set(parseNumber("int32", k), item); else out[k] = item;
    }
    return out;
  }
  if (d.array === "multidim") {
    if (!json || !Array.isArray(json.dims) || !Array.isArray(json.array)) {
      throw new Error(`${d.text}: {"dims": [...], "array": [...]} expected (column-major)`);
    }
    return { dims: json.dims.map(Number), array: arrayFrom(d, json.array) };
  }
  if (d.array === "vector") return arrayFrom(d, asList(json));
  if (isNumericBase(d.base)) return parseNumber(d.base, String(json));
  if (d.base === "string") return String(json);
  if (d.base === "cdouble" || d.base === "csingle") {
    if (!json || typeof json !== "object") throw new Error(`${d.text}: {"real": …, "imag": …} expected`);
    return { real: parseNumber("double", String(json.real)), imag: parseNumber("double", String(json.imag)) };
  }
  if (d.base === "varvalue") {
    // {type, value}: the value is typed by its own type, described as the device's definitions say
    if (json && typeof json === "object" && typeof json.type === "string" && "value" in json && d.describeValueType) {
      return { type: json.type, value: fromJson(d.describeValueType(json.type), json.value) };
    }
    return json;
  }
  if (d.kind === "enum") return parseEnum(d.enumValues, String(json));
  if (d.fields) {
    if (!json || typeof json !== "object" || Array.isArray(json)) throw new Error(`${d.text}: an object expected`);
    const out = {};
    for (const f of d.fields) {
      if (!(f.name in json)) throw new Error(`${d.text}: field ${f.name} missing`);
      out[f.name] = fromJson(f.type, json[f.name]);
    }
    return out;
  }
  return json;
}

function asList(json) {
  if (!Array.isArray(json)) throw new Error("a JSON array expected");
  return json;
}

/** True when editors show values of `d` as plain text (numbers, numeric vectors, strings), not JSON. */
export function isPlainText(d) {
  return !d.container && (!d.array || (d.array === "vector" && isNumericBase(d.base)))
    && (isNumericBase(d.base) || d.base === "string");
}

/** Editor text for a value of descriptor `d` (inverse of parseInput for the shapes parseInput reads as plain text). */
export function editorText(d, v) {
  if (v === undefined || v === null) return isPlainText(d) ? "" : "null";
  if (scalar(d) && d.base === "string") return v;
  if (scalar(d) && isNumericBase(d.base)) return typeof v === "number" ? numberText(v) : String(v);
  if (!d.container && d.array === "vector" && isNumericBase(d.base)) {
    return Array.from(v, (x) => (typeof x === "number" ? numberText(x) : String(x))).join(", ");
  }
  return JSON.stringify(toPlain(v));
}
