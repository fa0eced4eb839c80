// com.robotraconteur.pid.PIDParam (gains and limits of a PID loop) and com.robotraconteur.param
// ParameterInfo (a device parameter's name, type, units, range and default) as one line of text each,
// wherever they appear (a property, a function's result, a sensor's or camera's parameter_info list).

import { shortNumber } from "./geometry.js";
import { formatDataType } from "./datatype.js";

const num = (v) => (Number.isFinite(Number(v)) ? shortNumber(Number(v), 6) : "?");

/** "P 1.2, I 0.05, D 0.01; integral -5 … 5; command -10 … 10" of a PIDParam value, or null. */
export function formatPid(v) {
  if (!v || typeof v !== "object" || !("p" in v)) return null;
  return `P ${num(v.p)}, I ${num(v.i)}, D ${num(v.d)}; integral ${num(v.imin)} … ${num(v.imax)}; command ${num(v.cmd_min)} … ${num(v.cmd_max)}`;
}

/** A varvalue ({type, value}) as short text: numbers joined, a string quoted; "" for null. */
export function varText(v) {
  if (v === null || v === undefined) return "";
  if (typeof v !== "object" || !("type" in v)) return String(v);
  if (v.type === "string") return JSON.stringify(v.value);
  const a = v.value;
  if (ArrayBuffer.isView(a) || Array.isArray(a)) return Array.from(a, (x) => (typeof x === "number" ? shortNumber(x, 6) : String(x))).join(", ");
  return v.type;
}

/**
 * "exposure (double, ms): exposure time, default 10, 0.1 … 100" of a ParameterInfo; `ctx.descriptor`
 * gives the DataType's enum values (datatype.js).
 */
export function formatParameterInfo(v, ctx) {
  if (!v || typeof v !== "object") return null;
  const name = v.parameter_identifier?.name || "(unnamed)";
  const typeField = ctx?.descriptor?.fields?.find((f) => f.name === "data_type")?.type;
  const type = formatDataType(v.data_type, typeField);
  const units = Array.from(v.data_units ?? [], (u) => u?.display_units || u?.encoded_units).filter(Boolean).join(", ");
  const inner = [type, units].filter(Boolean).join(", ");
  const head = inner ? `${name} (${inner})` : name;
  const lo = varText(v.min_value), hi = varText(v.max_value), def = varText(v.default_value);
  const enumNames = v.enum_values && typeof v.enum_values === "object" ? Object.keys(v.enum_values instanceof Map ? Object.fromEntries(v.enum_values) : v.enum_values) : [];
  const parts = [v.description || "", def && `default ${def}`, (lo || hi) && `${lo || "…"} … ${hi || "…"}`, enumNames.length ? `one of ${enumNames.join(", ")}` : ""].filter(Boolean);
  return parts.length ? `${head}: ${parts.join(", ")}` : head;
}

export const renderers = [
  {
    type: "com.robotraconteur.pid.PIDParam",
    layout: { p: "double", i: "double", d: "double", imax: "double", imin: "double", cmd_max: "double", cmd_min: "double" },
    text: (v) => formatPid(v) ?? "(not a PIDParam)",
  },
  {
    type: "com.robotraconteur.param.ParameterInfo",
    layout: { parameter_identifier: "com.robotraconteur.identifier.Identifier", data_type: "com.robotraconteur.datatype.DataType", description: "string" },
    text: (v, ctx) => formatParameterInfo(v, ctx) ?? "(not a ParameterInfo)",
  },
];
