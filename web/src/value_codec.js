// Values between the page and the client package: text in editors -> typed values (typed arrays for
// numeric arrays, BigInt for int64, plain objects for structs, {dims, array} for multidim arrays,
// {real, imag} for complex numbers, {type, value} for varvalues), and values -> short display text.
// Structured inputs are JSON (JSON.parse); numbers JSON cannot hold are written as strings there
// ("NaN", "Infinity", "-Infinity", "-0"), as are 64-bit integers.

import { NUMERIC_ARRAYS, parseType, parseNumber, isNumericBase } from "./rr_types.js";

/**
 * Converts editor text to a value of `typeText`. Numbers and numeric vectors are plain text
 * ("1.5", "0.2, 0.4, 0.6"); strings are taken as written; everything else is JSON, converted field by
 * field with the struct definitions of `outline` (robdef_outline.js). Throws Error with the reason.
 */
export function parseInput(typeText, text, outline, scope) {
  const t = parseType(typeText);
  if (!t.container && !t.array) {
    if (isNumericBase(t.base)) return parseNumber(t.base, text);
    if (t.base === "string") return String(text);
    if (outline?.enumOf(t.base, scope)) return parseEnum(outline.enumOf(t.base, scope), text);
  }
  if (!t.container && t.array === "vector" && isNumericBase(t.base) && !String(text).trim().startsWith("[")) {
    const parts = String(text).split(/[\s,;]+/).filter((p) => p !== "");
    return toArray(t.base, parts.map((p) => parseNumber(t.base, p)));
  }
  let json;
  try { json = JSON.parse(text); } catch (e) { throw new Error(`JSON expected for ${typeText}: ${e.message}`); }
  return fromJson(typeText, json, outline, scope);
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

/** Converts parsed JSON to a value typed by `typeText` (see parseInput). */
export function fromJson(typeText, json, outline, scope) {
  const t = parseType(typeText);
  if (json === null && (t.container || t.array || !isNumericBase(t.base))) return null;
  if (t.container) {
    const inner = typeText.replace(/\{(int32|string|list)\}\s*$/, "");
    if (t.container === "list") return asList(json).map((x) => fromJson(inner, x, outline, scope));
    const out = t.container === "int32" ? new Map() : {};
    for (const [k, v] of Object.entries(json)) {
      const item = fromJson(inner, v, outline, scope);
      if (out instanceof Map) out.set(parseNumber("int32", k), item); else out[k] = item;
    }
    return out;
  }
  if (t.array === "multidim") {
    if (!json || !Array.isArray(json.dims) || !Array.isArray(json.array)) {
      throw new Error(`${typeText}: {"dims": [...], "array": [...]} expected (column-major)`);
    }
    return { dims: json.dims.map(Number), array: fromJson(`${t.base}[]`, json.array, outline, scope) };
  }
  if (t.array === "vector") {
    const items = asList(json);
    if (isNumericBase(t.base)) return toArray(t.base, items.map((x) => parseNumber(t.base, String(x))));
    return items.map((x) => fromJson(t.base, x, outline, scope));
  }
  if (isNumericBase(t.base)) return parseNumber(t.base, String(json));
  if (t.base === "string") return String(json);
  if (t.base === "cdouble" || t.base === "csingle") {
    if (!json || typeof json !== "object") throw new Error(`${typeText}: {"real": …, "imag": …} expected`);
    return { real: parseNumber("double", String(json.real)), imag: parseNumber("double", String(json.imag)) };
  }
  if (t.base === "varvalue") {
    // {type, value}: the value is typed by its own type text
    if (json && typeof json === "object" && typeof json.type === "string" && "value" in json) {
      return { type: json.type, value: fromJson(json.type, json.value, outline, scope) };
    }
    return json;
  }
  const def = outline?.typeOf(t.base, scope);
  if (def?.kind === "enum") return parseEnum(def.values, String(json));
  if (def && def.fields) {
    if (!json || typeof json !== "object" || Array.isArray(json)) throw new Error(`${typeText}: an object expected`);
    const out = {};
    for (const f of def.fields) {
      if (!(f.name in json)) throw new Error(`${typeText}: field ${f.name} missing`);
      out[f.name] = fromJson(f.type, json[f.name], outline, def.service);
    }
    return out;
  }
  return json;
}

function asList(json) {
  if (!Array.isArray(json)) throw new Error("a JSON array expected");
  return json;
}

/** A number as editor text: shortest round-trip form, keeping the sign of -0. */
export function numberText(x) {
  return Object.is(x, -0) ? "-0" : String(x);
}

function plainNumber(x) {
  return Number.isFinite(x) && !Object.is(x, -0) ? x : numberText(x);
}

/** Plain JSON-able form of a value (typed arrays as arrays, BigInt and non-finite numbers as text,
 * Maps as objects). */
export function toPlain(v) {
  if (typeof v === "bigint") return v.toString();
  if (typeof v === "number") return plainNumber(v);
  if (ArrayBuffer.isView(v)) return Array.from(v, (x) => (typeof x === "bigint" ? x.toString() : plainNumber(x)));
  if (v instanceof Map) return Object.fromEntries([...v].map(([k, x]) => [String(k), toPlain(x)]));
  if (Array.isArray(v)) return v.map(toPlain);
  if (v && typeof v === "object") return Object.fromEntries(Object.entries(v).map(([k, x]) => [k, toPlain(x)]));
  return v;
}

/** Short display text; long arrays are cut to `maxItems` with a count of the rest. */
export function formatValue(v, maxItems = 32) {
  if (v === undefined) return "(no value)";
  if (v === null) return "null";
  if (typeof v === "string") return JSON.stringify(v);
  if (typeof v === "number") return formatNumber(v);
  if (typeof v === "bigint" || typeof v === "boolean") return String(v);
  if (ArrayBuffer.isView(v) || Array.isArray(v)) {
    const items = Array.from(v.slice(0, maxItems), (x) => formatValue(x, maxItems));
    const more = v.length > maxItems ? `, … ${v.length - maxItems} more` : "";
    return `[${items.join(", ")}${more}]`;
  }
  if (v instanceof Map) {
    // maps have no order in RR: shown by key
    const entries = [...v].sort(([a], [b]) => (a < b ? -1 : a > b ? 1 : 0));
    return `{${entries.slice(0, maxItems).map(([k, x]) => `${k}: ${formatValue(x, maxItems)}`).join(", ")}}`;
  }
  if (typeof v === "object") {
    if (v.dims && v.array) return `${Array.from(v.dims).join("×")} ${formatValue(v.array, maxItems)}`;
    return `{${Object.entries(v).map(([k, x]) => `${k}: ${formatValue(x, maxItems)}`).join(", ")}}`;
  }
  return String(v);
}

function formatNumber(x) {
  if (Number.isInteger(x) || !Number.isFinite(x)) return numberText(x);
  return String(Number(x.toPrecision(6)));
}

/** Editor text for a value (inverse of parseInput for the shapes parseInput reads as plain text). */
export function editorText(typeText, v) {
  const t = parseType(typeText);
  const plainText = !t.container && (!t.array || (t.array === "vector" && isNumericBase(t.base)))
    && (isNumericBase(t.base) || t.base === "string");
  if (v === undefined || v === null) return plainText ? "" : "null";
  if (!t.container && !t.array && t.base === "string") return v;
  if (!t.container && !t.array && isNumericBase(t.base)) return typeof v === "number" ? numberText(v) : String(v);
  if (!t.container && t.array === "vector" && isNumericBase(t.base)) {
    return Array.from(v, (x) => (typeof x === "number" ? numberText(x) : String(x))).join(", ");
  }
  return JSON.stringify(toPlain(v));
}
