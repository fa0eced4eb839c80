// The generic text of a value as the client package gives it (typed arrays, BigInt, Maps, {dims,
// array} multidim arrays, plain objects): short display text, and the plain JSON-able form editors
// write. What a value whose type the page does not know (or has no renderer for) looks like.

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
