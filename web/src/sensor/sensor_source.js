// The sensor panel's pure logic (no page): which wire of a standard sensor carries its value, and that
// value as named axes with units. A WrenchSensor's wrench_sensor_value (force and torque in N and N·m,
// the geometry definitions' SI units), a VectorNSensor's vectorN_sensor_value, a FreeformSensor's
// freeform_sensor_value, else every Sensor's sensor_value (double[]); each only when the device's
// definitions give the member the standard type (an older or different layout: none, and the panel
// leaves the values to the generic view).

import { wrenchParts, WRENCH } from "../std/wrench.js";
import { siUnitText } from "../std/units.js";

const S = "com.robotraconteur.sensor";
const G = "com.robotraconteur.geometry";

/** The object types the sensor panel is for. */
export const SENSOR_TYPES = ["Sensor", "FreeformSensor", "Vector2Sensor", "Vector3Sensor", "Vector6Sensor", "WrenchSensor"]
  .map((n) => `${S}.${n}`);

const VECTORS = [
  { member: "vector6_sensor_value", type: `${G}.Vector6`, fields: ["alpha", "beta", "gamma", "x", "y", "z"] },
  { member: "vector3_sensor_value", type: `${G}.Vector3`, fields: ["x", "y", "z"] },
  { member: "vector2_sensor_value", type: `${G}.Vector2`, fields: ["x", "y"] },
];

const sameNames = (fields, names) => Array.isArray(fields) && fields.length === names.length
  && fields.every((f, i) => f.name === names[i] && f.type?.base === "double");

/**
 * The value source of a sensor object: { member, kind: "wrench" | "vector" | "freeform" | "array",
 * fields? } or null. `wires`: the object's readable wires ({name, ...}); `describe(member)` gives a
 * member's descriptor (views/context.js describeMember).
 */
export function sensorSource(wires, describe) {
  const byName = new Map(wires.map((m) => [m.name, m]));
  const typeOf = (name) => (byName.has(name) ? describe(byName.get(name))?.type ?? null : null);
  const wrench = typeOf("wrench_sensor_value");
  if (wrench?.qualified === WRENCH && wrench.renderer && !wrench.array && !wrench.container) {
    return { member: "wrench_sensor_value", kind: "wrench" };
  }
  for (const v of VECTORS) {
    const t = typeOf(v.member);
    if (t?.qualified === v.type && !t.array && !t.container && sameNames(t.fields, v.fields)) {
      return { member: v.member, kind: "vector", fields: v.fields };
    }
  }
  const free = typeOf("freeform_sensor_value");
  if (free?.base === "varvalue" && !free.array && !free.container) return { member: "freeform_sensor_value", kind: "freeform" };
  const plain = typeOf("sensor_value");
  if (plain?.base === "double" && plain.array === "vector" && !plain.container) return { member: "sensor_value", kind: "array" };
  return null;
}

/** The unit texts of a SensorInfo's `units` (SIUnit{list}), [] when absent. */
export function infoUnits(sensorInfo) {
  const list = sensorInfo?.units;
  if (!list || typeof list.length !== "number") return [];
  return Array.from(list, (u) => siUnitText(u) ?? "");
}

/** Unit i of n from the sensor's list: one per value, or one for all; "" otherwise. */
function unitAt(units, i, n) {
  if (units.length === n) return units[i] ?? "";
  if (units.length === 1) return units[0] ?? "";
  return "";
}

const finite = (x) => (typeof x === "bigint" ? Number(x) : Number(x));

/**
 * [{ name, value (number), unit }] of one value of `source`, with `units` the sensor's unit texts
 * (infoUnits); [] for a value that is not of the source's shape. A freeform value that is not a map
 * or list of numbers gives [{ name: "value", text }].
 */
export function sensorAxes(source, value, units = []) {
  if (!source || value === null || value === undefined) return [];
  if (source.kind === "wrench") {
    const w = wrenchParts(value);
    if (!w) return [];
    return [
      ...["x", "y", "z"].map((k) => ({ name: `force.${k}`, value: w.force[k], unit: "N" })),
      ...["x", "y", "z"].map((k) => ({ name: `torque.${k}`, value: w.torque[k], unit: "N·m" })),
    ];
  }
  if (source.kind === "vector") {
    const v = Array.isArray(value) && value.length === 1 && typeof value[0] === "object" ? value[0] : value;
    if (!v || typeof v !== "object") return [];
    const n = source.fields.length;
    if (ArrayBuffer.isView(v) || Array.isArray(v)) {
      if (v.length !== n) return [];
      return source.fields.map((f, i) => ({ name: f, value: finite(v[i]), unit: unitAt(units, i, n) }));
    }
    if (!source.fields.every((f) => typeof v[f] === "number")) return [];
    return source.fields.map((f, i) => ({ name: f, value: v[f], unit: unitAt(units, i, n) }));
  }
  if (source.kind === "array") {
    if (!(ArrayBuffer.isView(value) || Array.isArray(value))) return [];
    const n = value.length;
    return Array.from(value, (x, i) => ({ name: `[${i}]`, value: finite(x), unit: unitAt(units, i, n) }));
  }
  // freeform: a varvalue, as the client package gives it (a plain value, or {type, value})
  const inner = value && typeof value === "object" && "type" in value && "value" in value ? value.value : value;
  if (typeof inner === "number") return [{ name: "value", value: inner, unit: unitAt(units, 0, 1) }];
  if (ArrayBuffer.isView(inner) || Array.isArray(inner)) {
    if (Array.from(inner).every((x) => typeof x === "number" || typeof x === "bigint")) {
      const n = inner.length;
      return Array.from(inner, (x, i) => ({ name: `[${i}]`, value: finite(x), unit: unitAt(units, i, n) }));
    }
  }
  const entries = inner instanceof Map ? [...inner] : inner && typeof inner === "object" ? Object.entries(inner) : null;
  if (entries) {
    const numeric = entries.map(([k, x]) => {
      const y = x && typeof x === "object" && "value" in x ? x.value : x;
      const num = typeof y === "number" ? y : (ArrayBuffer.isView(y) || Array.isArray(y)) && y.length === 1 ? Number(y[0]) : NaN;
      return [String(k), num];
    });
    if (numeric.length && numeric.every(([, x]) => Number.isFinite(x))) {
      return numeric.map(([k, x], i) => ({ name: k, value: x, unit: unitAt(units, i, numeric.length) }));
    }
  }
  return [{ name: "value", text: JSON.stringify(inner, (k, x) => (typeof x === "bigint" ? String(x) : ArrayBuffer.isView(x) ? Array.from(x) : x)) }];
}

/** A sensor's value as text: up to 4 decimals, no "-0". */
export function axisText(x) {
  if (typeof x !== "number") return String(x);
  if (!Number.isFinite(x)) return String(x);
  const s = Number(x.toFixed(4));
  return String(Object.is(s, -0) ? 0 : s);
}

/** A short title for the panel by the source's kind. */
export function sensorTitle(source, types) {
  if (source?.kind === "wrench" || types.has(`${S}.WrenchSensor`)) return "Force/torque sensor";
  if (source?.kind === "vector") return `Vector sensor (${source.fields.length} axes)`;
  return "Sensor";
}
