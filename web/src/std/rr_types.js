// RR type text (robdef §Types) as the member list gives it: "double", "double[]", "uint8[*]",
// "int32[3]", "string{int32}", "SensorPacket", "varvalue". Split here once, by the TypeDescriber
// (describe.js), into the descriptors every view uses; and the numeric types' ranges.

/** Numeric scalar types and the typed array the client package uses for their arrays. */
export const NUMERIC_ARRAYS = {
  double: Float64Array, single: Float32Array,
  int8: Int8Array, uint8: Uint8Array, int16: Int16Array, uint16: Uint16Array,
  int32: Int32Array, uint32: Uint32Array, int64: BigInt64Array, uint64: BigUint64Array,
};

const INTEGER_RANGES = {
  int8: [-128, 127], uint8: [0, 255], int16: [-32768, 32767], uint16: [0, 65535],
  int32: [-2147483648, 2147483647], uint32: [0, 4294967295],
};

/**
 * Splits a type text. Returns { text, base, array: null | "vector" | "multidim", dims: number[] | null,
 * container: null | "int32" | "string" | "list" }. `dims` holds the fixed sizes written ("[3]", "[2,2]").
 */
export function parseType(text) {
  let t = String(text || "").trim();
  let container = null;
  const c = /^(.*)\{(int32|string|list)\}$/.exec(t);
  if (c) { t = c[1].trim(); container = c[2]; }
  let array = null, dims = null;
  const a = /^(.*)\[([^\]]*)\]$/.exec(t);
  if (a) {
    t = a[1].trim();
    const inner = a[2].trim();
    if (inner === "") array = "vector";
    else if (inner === "*") array = "multidim";
    else {
      dims = inner.split(",").map((d) => parseInt(d, 10));
      array = dims.length > 1 ? "multidim" : "vector";
    }
  }
  return { text: String(text || ""), base: t, array, dims, container };
}

export function isNumericBase(base) { return base in NUMERIC_ARRAYS || base === "bool"; }

/** A scalar or a vector of numbers (what a plot can show without knowing the struct): type text, or
 * anything with its parts ({base, array, container}: a type descriptor). */
export function isPlottable(type) {
  const t = typeof type === "string" ? parseType(type) : type;
  return !!t && !t.container && t.array !== "multidim" && isNumericBase(t.base);
}

/** Parses one number of a base type; int64/uint64 give BigInt. Throws a readable Error. */
export function parseNumber(base, text) {
  const s = String(text).trim();
  if (s === "") throw new Error(`a ${base} is needed`);
  if (base === "bool") {
    if (/^(true|1)$/i.test(s)) return true;
    if (/^(false|0)$/i.test(s)) return false;
    throw new Error(`not a bool: ${s}`);
  }
  if (base === "int64" || base === "uint64") {
    let v;
    try { v = BigInt(s); } catch { throw new Error(`not an integer: ${s}`); }
    if (base === "uint64" && v < 0n) throw new Error(`${s} is negative (uint64)`);
    return v;
  }
  const v = Number(s);
  if (!Number.isFinite(v) && !/^[+-]?(inf|infinity|nan)$/i.test(s)) throw new Error(`not a number: ${s}`);
  const range = INTEGER_RANGES[base];
  if (range) {
    if (!Number.isInteger(v)) throw new Error(`not an integer: ${s}`);
    if (v < range[0] || v > range[1]) throw new Error(`${s} is out of range for ${base}`);
  }
  return v;
}
