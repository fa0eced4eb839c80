// What a live plot takes from a typed value: which fields to leave out by default (identifiers,
// UUIDs, byte arrays, clock fields), which to start hidden (flag words, sequence numbers), and the
// value's own timestamp (a sensor's data_header.ts, a robot state's ts) for the time axis.

import { timeSeconds } from "./datetime.js";
import { enumName, formatFlags } from "./enums.js";

const D = "com.robotraconteur.datetime";
/** Clock types: the time axis may come from them; they are never plotted as series. */
export const TIME_TYPES = new Set([`${D}.TimeSpec2`, `${D}.TimeSpec3`, `${D}.DateTimeUTC`, `${D}.DateTimeLocal`]);
/** Types left out of plots by default: clocks, identifiers, UUIDs and sensor source descriptions. */
export const LEFT_OUT_TYPES = new Set([...TIME_TYPES, `${D}.ClockInfo`, "com.robotraconteur.uuid.UUID",
  "com.robotraconteur.identifier.Identifier", "com.robotraconteur.sensordata.SensorDataSourceInfo"]);

const MAX_VECTOR = 16;

/**
 * How a plot treats field `field` ({name, type: descriptor, flags?} of describe.js): "omit" (left
 * out: the types above, byte arrays, strings, varvalues), "hidden" (a series that starts hidden: flag
 * words, names ending in seqno) or "show".
 */
export function plotRole(field) {
  const t = field?.type;
  const named = t?.element ?? t;
  if (!t) return "show";
  if (LEFT_OUT_TYPES.has(named?.qualified)) return "omit";
  if ((t.array || t.container) && (named.base === "uint8" || named.base === "int8")) return "omit";
  if (named.base === "string" || named.base === "varvalue" || named.base === "varobject") return "omit";
  if (field.flags || /(^|_)seqno$/.test(field.name || "")) return "hidden";
  return "show";
}

/** The predicate plots use: true when field `field` is left out by default (plotRole "omit"). */
export function leaveOutOfPlot(field) { return plotRole(field) === "omit"; }

/**
 * [[seriesName, number, hiddenAtFirst, label?], ...] of a value typed by descriptor `d` (describe.js):
 * numbers, enums, bools, short numeric vectors and the fields of structures, pods and namedarrays,
 * without the fields plotRole leaves out. `label` is the readout's text where the number means a
 * name: an enum value's name ("jog"), a flag word's set flags ("ready | enabled"), an enum code.
 */
export function typedNumericFields(value, d, prefix = "") {
  const out = [];
  collect(value, d, prefix, false, out, 0, null);
  return out;
}

/** The readout text of number `v` of type `d` in field `field`, or undefined (the number itself). */
function numberLabel(v, d, field) {
  if (field?.flags) return formatFlags(field.flags, v);
  const values = d?.enumValues ?? field?.codes;
  if (values) return enumName(values, v) ?? `${v} (not a value of the enum)`;
  return undefined;
}

function collect(v, d, name, hidden, out, depth, field) {
  if (depth > 6 || v === null || v === undefined) return;
  const push = (x) => {
    const label = numberLabel(v, d, field);
    out.push(label === undefined ? [name || "value", x, hidden] : [name || "value", x, hidden, label]);
  };
  if (typeof v === "number") push(v);
  else if (typeof v === "bigint") push(Number(v));
  else if (typeof v === "boolean") out.push([name || "value", v ? 1 : 0, hidden]);
  else if ((ArrayBuffer.isView(v) || Array.isArray(v)) && !(d?.array === "multidim") && v.length <= MAX_VECTOR) {
    Array.from(v).forEach((x, i) => collect(x, d?.element, `${name}[${i}]`, hidden, out, depth + 1, field?.codes ? { codes: field.codes } : null));
  } else if (d?.fields && typeof v === "object" && !ArrayBuffer.isView(v)) {
    for (const f of d.fields) {
      const role = plotRole(f);
      if (role !== "omit") collect(v[f.name], f.type, name ? `${name}.${f.name}` : f.name, hidden || role === "hidden", out, depth + 1, f);
    }
  }
}

/**
 * The value's own timestamp: the first field (breadth first, 4 levels deep) of a clock type whose
 * layout the renderer registry recognised and that is set. { seconds (since the epoch, on the
 * sender's clock), path ("image_info.data_header.ts"), type } or null.
 */
export function sensorTimestamp(value, d) {
  let level = [[value, d, ""]];
  for (let depth = 0; depth < 4 && level.length; depth++) {
    const next = [];
    for (const [v, desc, path] of level) {
      if (!v || typeof v !== "object" || !desc?.fields) continue;
      for (const f of desc.fields) {
        const fv = v[f.name];
        const p = path ? `${path}.${f.name}` : f.name;
        if (TIME_TYPES.has(f.type.qualified) && f.type.renderer) {
          const seconds = timeSeconds(fv);
          if (seconds) return { seconds, path: p, type: f.type.qualified };
        } else if (f.type.fields) next.push([fv, f.type, p]);
      }
    }
    level = next;
  }
  return null;
}
