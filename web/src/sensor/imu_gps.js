// The IMU and GPS panels' pure logic (no page): an orientation's axes seen from a fixed viewpoint (the
// gizmo), and a GPS track as metres east and north of its first fix.

import { namedFields } from "../std/geometry.js";

/** The rotation matrix (rows) of a Quaternion {w, x, y, z} (normalised), or null. */
export function rotationMatrix(q) {
  q = namedFields(q, ["w", "x", "y", "z"]);
  if (!q) return null;
  const n = Math.hypot(q.w, q.x, q.y, q.z);
  if (!(n > 0) || !Number.isFinite(n)) return null;
  const w = q.w / n, x = q.x / n, y = q.y / n, z = q.z / n;
  return [
    [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
    [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
    [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
  ];
}

// the viewpoint: looking at the origin from (1, 1, 0.8) (x to the lower left, y to the lower right, z up)
const AZ = Math.PI / 4, EL = Math.atan2(0.8, Math.SQRT2);
const RIGHT = [-Math.sin(AZ), Math.cos(AZ), 0];
const UP = [-Math.sin(EL) * Math.cos(AZ), -Math.sin(EL) * Math.sin(AZ), Math.cos(EL)];
const TOWARD = [Math.cos(EL) * Math.cos(AZ), Math.cos(EL) * Math.sin(AZ), Math.sin(EL)];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];

/**
 * The rotated x, y, z axes as seen from the fixed viewpoint: [{ axis: "x"|"y"|"z", dx, dy (screen,
 * y down, unit length before projection), depth (toward the viewer: larger is nearer) }], farthest
 * first (the drawing order), or null for an invalid quaternion.
 */
export function gizmoAxes(q) {
  const R = rotationMatrix(q);
  if (!R) return null;
  return ["x", "y", "z"].map((axis, i) => {
    const v = [R[0][i], R[1][i], R[2][i]];
    return { axis, dx: dot(v, RIGHT), dy: -dot(v, UP), depth: dot(v, TOWARD) };
  }).sort((a, b) => a.depth - b.depth);
}

const EARTH_RADIUS = 6371008.8;  // mean radius, metres

/** Metres { east, north } of (lat, lon) from (lat0, lon0), degrees (equirectangular: fine over a few km). */
export function localMetres(lat, lon, lat0, lon0) {
  const rad = Math.PI / 180;
  return { east: (lon - lon0) * rad * Math.cos(lat0 * rad) * EARTH_RADIUS, north: (lat - lat0) * rad * EARTH_RADIUS };
}

/** A bounded track of fixes: push(lat, lon) keeps the newest `max`; points() in metres from the first. */
export class GpsTrack {
  constructor(max = 2000) { this.max = max; this.fixes = []; this.origin = null; }
  push(lat, lon) {
    if (!Number.isFinite(lat) || !Number.isFinite(lon) || Math.abs(lat) > 90 || Math.abs(lon) > 180) return false;
    this.origin ??= [lat, lon];
    this.fixes.push([lat, lon]);
    if (this.fixes.length > this.max) this.fixes.splice(0, this.fixes.length - this.max);
    return true;
  }
  points() { return this.origin ? this.fixes.map(([a, b]) => localMetres(a, b, this.origin[0], this.origin[1])) : []; }
}
