// com.robotraconteur.geometry.Wrench (namedarray: Vector3 torque, Vector3 force), in SI units as the
// geometry definitions state: force in newtons, torque in newton metres. Shown force first, as a
// force/torque sensor's readout is read.

import { namedFields, shortNumber } from "./geometry.js";

const G = "com.robotraconteur.geometry";
const XYZ = ["x", "y", "z"];

/** { torque: {x, y, z}, force: {x, y, z} } of a Wrench value (object, or 6 numbers torque then force), or null. */
export function wrenchParts(v) {
  if (Array.isArray(v) && v.length === 1 && v[0] && typeof v[0] === "object") v = v[0];
  if (v && (ArrayBuffer.isView(v) || Array.isArray(v))) {
    if (v.length !== 6) return null;
    const n = Array.from(v, Number);
    return { torque: { x: n[0], y: n[1], z: n[2] }, force: { x: n[3], y: n[4], z: n[5] } };
  }
  const torque = namedFields(v?.torque, XYZ), force = namedFields(v?.force, XYZ);
  return torque && force ? { torque, force } : null;
}

const vec = (p, digits) => `(${XYZ.map((k) => shortNumber(p[k], digits)).join(", ")})`;

/** "force (1, 2, 3) N, torque (0.1, 0, 0) N·m" of a Wrench value, or null. */
export function formatWrench(v, digits = 4) {
  const w = wrenchParts(v);
  return w ? `force ${vec(w.force, digits)} N, torque ${vec(w.torque, digits)} N·m` : null;
}

export const WRENCH = `${G}.Wrench`;

export const renderers = [
  { type: WRENCH, layout: { torque: `${G}.Vector3`, force: `${G}.Vector3` }, text: (v) => formatWrench(v) ?? "(invalid wrench)" },
];
