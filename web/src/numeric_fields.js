// Numbers to plot out of a value: scalars, short numeric vectors and struct fields, flattened to
// named series ("robot_position[0]", "state.time"). Known packet layouts are decoded first.

import { decodeKnown } from "./packet_layouts.js";

const MAX_VECTOR = 16;

/** [[seriesName, number], ...] for `value`; `qualifiedType` picks a known layout (packet_layouts.js). */
export function numericFields(value, qualifiedType, prefix = "") {
  const known = decodeKnown(qualifiedType, value);
  if (known) return known;
  const out = [];
  collect(value, prefix, out, 0);
  return out;
}

function collect(v, name, out, depth) {
  if (typeof v === "number") out.push([name || "value", v]);
  else if (typeof v === "bigint") out.push([name || "value", Number(v)]);
  else if (typeof v === "boolean") out.push([name || "value", v ? 1 : 0]);
  else if ((ArrayBuffer.isView(v) || Array.isArray(v)) && v.length <= MAX_VECTOR) {
    Array.from(v).forEach((x, i) => collect(x, `${name}[${i}]`, out, depth + 1));
  } else if (v && typeof v === "object" && !ArrayBuffer.isView(v) && !Array.isArray(v) && !(v instanceof Map) && depth < 4) {
    if ("dims" in v && "array" in v) return;
    for (const [k, x] of Object.entries(v)) collect(x, name ? `${name}.${k}` : k, out, depth + 1);
  }
}
