// com.robotraconteur.pointcloud PointCloud, PointCloudf, PointCloud2, PointCloud2f and their Part forms:
// points in metres (x, y, z in the sensor's frame), PointCloud2's points with an intensity, a normal and a
// colour (PixelRGBFloatPacked: as PCL packs it, the bits of the float are 0x00RRGGBB). A point that is not
// finite is no point (clouds that are not `is_dense` mark holes with NaN).
//
// The work is split so that it can leave the page's thread: packCloud() copies the points out of the
// client package's objects into flat typed arrays (on the page: the objects are there), colorCloud() drops
// the holes, finds the bounds and colours each point (in pointcloud_worker.js, through CloudDecoder),
// giving what a WebGL view uploads as it is. A picture of a cloud (the renderer's `image` hook, wherever a
// cloud appears: a function's result, a property, a replayed recording) is drawn from above at an angle.

import { jetTable } from "./colormap.js";

const PC = "com.robotraconteur.pointcloud";

/** The colour modes: the cloud's own colour, its intensity or its height (z) through the jet map. */
export const COLOR_MODES = Object.freeze(["rgb", "intensity", "height"]);

/** The point (an object with x, y, z) of one item of a cloud's points: a Point, or a PointCloud2Point's `point`. */
const pointOf = (p) => (p && typeof p.point === "object" ? p.point : p);

/**
 * The points of `cloud` (any PointCloud* value as the client package gives it: points an Array of objects)
 * as flat arrays: { count, positions: Float32Array(3·count), intensity: Float32Array | null, rgb:
 * Float32Array | null (the packed colour floats) }. Intensity and rgb only for PointCloud2 points.
 * Nothing is checked here but the shape; colorCloud() drops points that are not finite.
 */
export function packCloud(cloud) {
  const points = cloud?.points;
  const count = points && typeof points.length === "number" && typeof points !== "string" ? points.length : 0;
  const positions = new Float32Array(3 * count);
  const first = count ? points[0] : null;
  const v2 = !!first && typeof first.point === "object";
  const intensity = v2 && typeof first.intensity === "number" ? new Float32Array(count) : null;
  const rgb = v2 && typeof first.rgb?.rgb === "number" ? new Float32Array(count) : null;
  for (let i = 0, o = 0; i < count; i++, o += 3) {
    const item = points[i];
    const p = pointOf(item);
    if (!p) { positions[o] = positions[o + 1] = positions[o + 2] = NaN; continue; }
    positions[o] = p.x; positions[o + 1] = p.y; positions[o + 2] = p.z;
    if (intensity) intensity[i] = item.intensity;
    if (rgb) rgb[i] = item.rgb?.rgb;
  }
  return { count, positions, intensity, rgb };
}

/** The packed colour float as [r, g, b] bytes (0x00RRGGBB in the float's bits). */
export function unpackRgb(f) {
  const u = new Uint32Array(new Float32Array([f]).buffer)[0];
  return [(u >>> 16) & 255, (u >>> 8) & 255, u & 255];
}

/** The colour mode used for `packed` when `wanted` is "auto" (or not available): rgb, else intensity, else height. */
export function colorModeFor(packed, wanted = "auto") {
  const has = { rgb: !!packed?.rgb, intensity: !!packed?.intensity, height: true };
  if (wanted !== "auto" && has[wanted]) return wanted;
  return has.rgb ? "rgb" : has.intensity ? "intensity" : "height";
}

/**
 * The drawable cloud of `packed` (packCloud): { count, positions: Float32Array(3·count) of the finite
 * points only, colors: Uint8Array(3·count), min: [x, y, z], max: [x, y, z] (null when no point), mode
 * (the colour mode used), range: [lo, hi] of the value the jet map spans (intensity or z), or null for
 * rgb }. `opts.mode`: "auto" | "rgb" | "intensity" | "height"; `opts.range` fixes the jet map's span.
 */
export function colorCloud(packed, opts = {}) {
  const n = packed?.count || 0;
  const src = packed?.positions;
  const mode = colorModeFor(packed, opts.mode);
  const positions = new Float32Array(3 * n);
  const keep = new Uint32Array(n);
  const min = [Infinity, Infinity, Infinity], max = [-Infinity, -Infinity, -Infinity];
  let k = 0;
  for (let i = 0; i < n; i++) {
    const x = src[3 * i], y = src[3 * i + 1], z = src[3 * i + 2];
    if (!Number.isFinite(x) || !Number.isFinite(y) || !Number.isFinite(z)) continue;
    positions[3 * k] = x; positions[3 * k + 1] = y; positions[3 * k + 2] = z;
    if (x < min[0]) min[0] = x; if (x > max[0]) max[0] = x;
    if (y < min[1]) min[1] = y; if (y > max[1]) max[1] = y;
    if (z < min[2]) min[2] = z; if (z > max[2]) max[2] = z;
    keep[k++] = i;
  }
  const colors = new Uint8Array(3 * k);
  let range = null;
  if (mode === "rgb") {
    const bits = new Uint32Array(packed.rgb.buffer, packed.rgb.byteOffset, packed.rgb.length);
    for (let j = 0; j < k; j++) {
      const u = bits[keep[j]];
      colors[3 * j] = (u >>> 16) & 255; colors[3 * j + 1] = (u >>> 8) & 255; colors[3 * j + 2] = u & 255;
    }
  } else {
    const value = mode === "intensity" ? (j) => packed.intensity[keep[j]] : (j) => positions[3 * j + 2];
    range = opts.range || null;
    if (!range) {
      let lo = Infinity, hi = -Infinity;
      for (let j = 0; j < k; j++) { const v = value(j); if (v < lo) lo = v; if (v > hi) hi = v; }
      range = lo <= hi ? [lo, hi] : [0, 1];
    }
    const jet = jetTable(), span = range[1] - range[0];
    for (let j = 0; j < k; j++) {
      const v = value(j);
      const t = span > 0 ? (v - range[0]) / span : 0.5;
      const c = Number.isFinite(t) ? Math.round(Math.max(0, Math.min(1, t)) * 255) * 3 : 0;
      colors[3 * j] = jet[c]; colors[3 * j + 1] = jet[c + 1]; colors[3 * j + 2] = jet[c + 2];
    }
  }
  return {
    count: k, positions: k === n ? positions : positions.slice(0, 3 * k), colors, mode, range,
    min: k ? min : null, max: k ? max : null,
  };
}

/**
 * Puts PointCloud*Part values back into whole packed clouds (packCloud's form): parts of one cloud come in
 * order, points_offset 0 first, each starting where the one before ended, until points_total_len. A part
 * out of order, or a cloud begun again before it was whole, drops the cloud begun (counted in
 * `dropped`); parts before the first offset 0 are counted in `stray`. Clouds over `maxPoints` are refused.
 */
export class CloudAssembler {
  constructor(maxPoints = 4 << 20) { this.maxPoints = maxPoints; this.cloud = null; this.filled = 0; this.dropped = 0; this.stray = 0; }

  /** The whole packed cloud this part completes ({ count, positions, intensity, rgb, part }), or null. */
  push(part) {
    const offset = Number(part?.points_offset), total = Number(part?.points_total_len);
    const packed = packCloud(part);
    if (!Number.isInteger(offset) || !Number.isInteger(total) || total <= 0 || total > this.maxPoints || offset + packed.count > total) {
      if (this.cloud) this.dropped++;
      this.cloud = null;
      return null;
    }
    if (offset === 0) {
      if (this.cloud) this.dropped++;
      this.cloud = {
        count: total, positions: new Float32Array(3 * total),
        intensity: packed.intensity ? new Float32Array(total) : null, rgb: packed.rgb ? new Float32Array(total) : null, part,
      };
      this.filled = 0;
    }
    if (!this.cloud) { this.stray++; return null; }
    if (offset !== this.filled) { this.dropped++; this.cloud = null; return null; }
    const c = this.cloud;
    c.positions.set(packed.positions, 3 * offset);
    if (c.intensity) { if (packed.intensity) c.intensity.set(packed.intensity, offset); else c.intensity = null; }
    if (c.rgb) { if (packed.rgb) c.rgb.set(packed.rgb, offset); else c.rgb = null; }
    this.filled += packed.count;
    if (this.filled < total) return null;
    this.cloud = null;
    return c;
  }
}

const num = (x) => (typeof x === "number" && Number.isFinite(x) ? x : null);
const short = (x) => String(Math.round(x * 1000) / 1000);

/** "1.2 × 0.8 × 0.4 m at (0, 0, 0.2)" of a BoundingBox (centre pose, size), or null without a size. */
export function boundsText(box) {
  const s = box?.size, p = box?.center?.pose?.position;
  if (!s || num(s.width) === null) return null;
  const at = p && num(p.x) !== null ? ` at (${short(p.x)}, ${short(p.y)}, ${short(p.z)})` : "";
  return `${short(s.width)} × ${short(s.height)} × ${short(s.depth)} m${at}`;
}

/** "20000 points, dense, 1.2 × 0.8 × 0.4 m at (0, 0, 0.2)" of a PointCloud*. */
export function cloudText(cloud) {
  const n = cloud?.points?.length ?? 0;
  const parts = [`${n} point${n === 1 ? "" : "s"}`];
  if (cloud && typeof cloud.is_dense === "boolean") parts.push(cloud.is_dense ? "dense" : "not dense");
  const b = boundsText(cloud?.bounds);
  if (b) parts.push(b);
  return parts.join(", ");
}

/** "points 0 to 6666 of 20000" of a PointCloud*Part. */
function partText(p) {
  const n = p?.points?.length ?? 0, o = Number(p?.points_offset);
  return `points ${o} to ${o + n - 1} of ${Number(p?.points_total_len)}`;
}

const PICTURE = 320;

/**
 * `drawn` (colorCloud) projected onto a 2D context of size width × height, seen from the front-left above
 * (azimuth -60°, elevation 30°, z up), farthest points first, fitted to its bounds. Returns the points drawn.
 */
export function drawCloud(g, drawn, width, height, { background = "#f4f6f9", pointSize = 2 } = {}) {
  g.fillStyle = background;
  g.fillRect(0, 0, width, height);
  if (!drawn?.count) return 0;
  const az = (-60 * Math.PI) / 180, el = (30 * Math.PI) / 180;
  const ca = Math.cos(az), sa = Math.sin(az), ce = Math.cos(el), se = Math.sin(el);
  const c = [0, 1, 2].map((i) => (drawn.min[i] + drawn.max[i]) / 2);
  const n = drawn.count, p = drawn.positions;
  const u = new Float32Array(n), v = new Float32Array(n), depth = new Float32Array(n);
  let ext = 1e-9;
  for (let i = 0; i < n; i++) {
    const x = p[3 * i] - c[0], y = p[3 * i + 1] - c[1], z = p[3 * i + 2] - c[2];
    // view from direction (cos az · ce, sin az · ce, se) towards the centre: right = (-sin az, cos az, 0)
    u[i] = -sa * x + ca * y;
    v[i] = -se * (ca * x + sa * y) + ce * z;
    depth[i] = ce * (ca * x + sa * y) + se * z;
    ext = Math.max(ext, Math.abs(u[i]), Math.abs(v[i]));
  }
  const scale = (0.45 * Math.min(width, height)) / ext;
  const order = Array.from({ length: n }, (_, i) => i).sort((a, b) => depth[a] - depth[b]);
  const img = g.getImageData(0, 0, width, height);
  const d = img.data;
  for (const i of order) {
    const px = Math.round(width / 2 + u[i] * scale), py = Math.round(height / 2 - v[i] * scale);
    for (let dy = 0; dy < pointSize; dy++) {
      for (let dx = 0; dx < pointSize; dx++) {
        const x = px + dx, y = py + dy;
        if (x < 0 || y < 0 || x >= width || y >= height) continue;
        const o = (y * width + x) * 4;
        d[o] = drawn.colors[3 * i]; d[o + 1] = drawn.colors[3 * i + 1]; d[o + 2] = drawn.colors[3 * i + 2]; d[o + 3] = 255;
      }
    }
  }
  g.putImageData(img, 0, 0);
  return n;
}

/** The cloud as an RGBA picture (a FrameView draws it wherever a PointCloud value appears); needs OffscreenCanvas. */
function cloudImage(cloud) {
  if (typeof OffscreenCanvas === "undefined") return { ok: false, error: { code: "no_canvas", message: "no OffscreenCanvas to draw the cloud" } };
  if (!cloud?.points || typeof cloud.points.length !== "number") return { ok: false, error: { code: "no_points", message: "the cloud has no points" } };
  const c = new OffscreenCanvas(PICTURE, PICTURE);
  const g = c.getContext("2d");
  drawCloud(g, colorCloud(packCloud(cloud)), PICTURE, PICTURE);
  return { ok: true, width: PICTURE, height: PICTURE, data: g.getImageData(0, 0, PICTURE, PICTURE).data, encoding: "point cloud" };
}

const BOX = { G: "com.robotraconteur.geometry.BoundingBox", F: "com.robotraconteur.geometryf.BoundingBox" };
const cloudLayout = (box, point) => ({ bounds: box, is_dense: "bool", points: `${point}[]` });
const partLayout = (box, point) => ({ ...cloudLayout(box, point), points_offset: "uint32", points_total_len: "uint32" });

/** The renderers of the point cloud structures: text everywhere, a picture for whole clouds. */
export const renderers = [
  { type: `${PC}.PointCloud`, layout: cloudLayout(BOX.G, "com.robotraconteur.geometry.Point"), text: cloudText, image: cloudImage },
  { type: `${PC}.PointCloudf`, layout: cloudLayout(BOX.F, "com.robotraconteur.geometryf.Point"), text: cloudText, image: cloudImage },
  { type: `${PC}.PointCloud2`, layout: cloudLayout(BOX.G, `${PC}.PointCloud2Point`), text: cloudText, image: cloudImage },
  { type: `${PC}.PointCloud2f`, layout: cloudLayout(BOX.F, `${PC}.PointCloud2Pointf`), text: cloudText, image: cloudImage },
  { type: `${PC}.PointCloudPart`, layout: partLayout(BOX.G, "com.robotraconteur.geometry.Point"), text: partText },
  { type: `${PC}.PointCloudPartf`, layout: partLayout(BOX.F, "com.robotraconteur.geometryf.Point"), text: partText },
  { type: `${PC}.PointCloud2Part`, layout: partLayout(BOX.G, `${PC}.PointCloud2Point`), text: partText },
  { type: `${PC}.PointCloud2Partf`, layout: partLayout(BOX.F, `${PC}.PointCloud2Pointf`), text: partText },
];

/** The whole and part cloud types the panel reads. */
export const CLOUD_TYPES = Object.freeze(renderers.slice(0, 4).map((r) => r.type));
export const CLOUD_PART_TYPES = Object.freeze(renderers.slice(4).map((r) => r.type));
