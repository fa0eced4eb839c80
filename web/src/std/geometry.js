// com.robotraconteur.geometry Pose (namedarray: Quaternion orientation, Point position) and Transform
// (Quaternion rotation, Vector3 translation) as a position in metres plus roll, pitch and yaw in
// degrees. Quaternion fields are w, x, y, z (w first). Roll, pitch and yaw are the fixed-axis x-y-z
// angles: R = Rz(yaw) · Ry(pitch) · Rx(roll).

/**
 * A {w, x, y, z} / {x, y, z} namedarray value (fields `names`), also from a flat array of numbers in
 * field order; null when it is neither.
 */
export function namedFields(v, names) {
  if (v && (ArrayBuffer.isView(v) || Array.isArray(v))) {
    if (v.length !== names.length) return null;
    return Object.fromEntries(names.map((n, i) => [n, Number(v[i])]));
  }
  if (!v || typeof v !== "object" || !names.every((n) => typeof v[n] === "number")) return null;
  return v;
}

/**
 * [roll, pitch, yaw] in radians of a Quaternion value {w, x, y, z} (normalised first), or null for a
 * zero or non-numeric quaternion. Pitch is in [-π/2, π/2]; at ±π/2 (gimbal lock) roll is 0.
 */
export function quaternionToRpy(q) {
  q = namedFields(q, ["w", "x", "y", "z"]);
  if (!q) return null;
  const n = Math.hypot(q.w, q.x, q.y, q.z);
  if (!(n > 0) || !Number.isFinite(n)) return null;
  const w = q.w / n, x = q.x / n, y = q.y / n, z = q.z / n;
  const sinPitch = 2 * (w * y - z * x);
  if (Math.abs(sinPitch) >= 1 - 1e-12) {
    // gimbal lock: only yaw ∓ roll is defined; all of it given to yaw
    return [0, Math.sign(sinPitch) * Math.PI / 2, -2 * Math.sign(sinPitch) * Math.atan2(x, w)];
  }
  return [
    Math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y)),
    Math.asin(sinPitch),
    Math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z)),
  ];
}

/** A number with at most `digits` decimals, without "-0". */
export function shortNumber(v, digits) {
  const s = Number(v.toFixed(digits));
  return String(Object.is(s, -0) ? 0 : s);
}

function vectorText(p) { return `(${shortNumber(p.x, 4)}, ${shortNumber(p.y, 4)}, ${shortNumber(p.z, 4)})`; }

/** "rpy (0, 0, 90)°" of a Quaternion value, or null. */
export function formatRotation(q) {
  const rpy = quaternionToRpy(q);
  return rpy ? `rpy (${rpy.map((a) => shortNumber((a * 180) / Math.PI, 2)).join(", ")})°` : null;
}

/** "position (0.1, 0.2, 0.3) m, rpy (0, 0, 90)°" of a Pose value (also 7 numbers w x y z x y z), or null. */
export function formatPose(v) {
  if (v && (ArrayBuffer.isView(v) || Array.isArray(v)) && v.length === 7) {
    v = { orientation: Array.from(v).slice(0, 4), position: Array.from(v).slice(4) };
  }
  const p = namedFields(v?.position, ["x", "y", "z"]);
  const r = formatRotation(v?.orientation);
  return p && r ? `position ${vectorText(p)} m, ${r}` : null;
}

/** "translation (0.1, 0.2, 0.3) m, rpy (0, 0, 90)°" of a Transform value, or null. */
export function formatTransform(v) {
  if (v && (ArrayBuffer.isView(v) || Array.isArray(v)) && v.length === 7) {
    v = { rotation: Array.from(v).slice(0, 4), translation: Array.from(v).slice(4) };
  }
  const p = namedFields(v?.translation, ["x", "y", "z"]);
  const r = formatRotation(v?.rotation);
  return p && r ? `translation ${vectorText(p)} m, ${r}` : null;
}

const G = "com.robotraconteur.geometry";
const QUATERNION = { w: "double", x: "double", y: "double", z: "double" };
const XYZ = { x: "double", y: "double", z: "double" };

export const renderers = [
  { type: `${G}.Quaternion`, layout: QUATERNION, text: (v) => formatRotation(v) ?? "(invalid quaternion)" },
  { type: `${G}.Point`, layout: XYZ },
  { type: `${G}.Vector3`, layout: XYZ },
  {
    type: `${G}.Pose`, layout: { orientation: `${G}.Quaternion`, position: `${G}.Point` },
    text: (v) => formatPose(v) ?? "(invalid pose)",
  },
  {
    type: `${G}.Transform`, layout: { rotation: `${G}.Quaternion`, translation: `${G}.Vector3` },
    text: (v) => formatTransform(v) ?? "(invalid transform)",
  },
];
