// com.robotraconteur.laserscan LaserScan and LaserScanf (and their Part forms): a planar scan as points
// and a top-down picture. Ranges are metres along rays at angle_min + i · angle_increment (radians,
// counter-clockwise from the scanner's x axis, x forward, y left); a range outside
// [range_min, range_max], or not finite, is no return. Intensities colour the points (the "jet" map
// over the scan's own intensity range); without them each point takes its PixelRGB colour when the
// scan has one per range, else one colour.

import { jetTable } from "./colormap.js";

function jetColor(f) {
  const t = jetTable(), i = Math.round(f * 255) * 3;
  return [t[i], t[i + 1], t[i + 2]];
}

const L = "com.robotraconteur.laserscan";

/** The scan's info as numbers: { angleMin, angleMax, angleIncrement, rangeMin, rangeMax, scanTime, count }. */
export function scanGeometry(scan) {
  const i = scan?.scan_info || {};
  const num = (x, d = 0) => (typeof x === "number" && Number.isFinite(x) ? x : d);
  const count = scan?.ranges?.length ?? 0;
  const angleMin = num(i.angle_min);
  let angleIncrement = num(i.angle_increment);
  if (!angleIncrement && count > 1) angleIncrement = (num(i.angle_max) - angleMin) / (count - 1);
  return {
    angleMin, angleMax: num(i.angle_max, angleMin + angleIncrement * Math.max(0, count - 1)), angleIncrement,
    rangeMin: num(i.range_min), rangeMax: num(i.range_max, Infinity) || Infinity, scanTime: num(i.scan_time), count,
  };
}

/**
 * The scan's returns as points: { x: Float32Array, y: Float32Array, index: Uint32Array (the range's
 * index), n, maxRange (the farthest return) }, in metres.
 */
export function scanPoints(scan) {
  const g = scanGeometry(scan);
  const ranges = scan?.ranges;
  const n = g.count;
  const x = new Float32Array(n), y = new Float32Array(n), index = new Uint32Array(n);
  let k = 0, maxRange = 0;
  for (let i = 0; i < n; i++) {
    const r = Number(ranges[i]);
    if (!Number.isFinite(r) || r < g.rangeMin || r > g.rangeMax || r <= 0) continue;
    const a = g.angleMin + i * g.angleIncrement;
    x[k] = r * Math.cos(a);
    y[k] = r * Math.sin(a);
    index[k] = i;
    k++;
    if (r > maxRange) maxRange = r;
  }
  return { x, y, index, n: k, maxRange };
}

/** [lo, hi] of the finite intensities, or null when the scan has none for its ranges. */
export function intensityRange(scan) {
  const v = scan?.intensities;
  if (!v || v.length !== (scan?.ranges?.length ?? -1) || !v.length) return null;
  let lo = Infinity, hi = -Infinity;
  for (let i = 0; i < v.length; i++) {
    const x = Number(v[i]);
    if (!Number.isFinite(x)) continue;
    if (x < lo) lo = x;
    if (x > hi) hi = x;
  }
  return lo <= hi ? [lo, hi] : null;
}

/** The colour [r, g, b] of range i: by intensity (jet over `range`), else the scan's PixelRGB, else blue. */
export function pointColor(scan, i, range) {
  if (range) {
    const t = range[1] > range[0] ? (Number(scan.intensities[i]) - range[0]) / (range[1] - range[0]) : 0.5;
    return jetColor(Math.max(0, Math.min(1, t)));
  }
  const c = scan?.color;
  if (c && c.length === scan.ranges.length && c[i]) return [c[i].r ?? 0, c[i].g ?? 0, c[i].b ?? 0];
  return [31, 119, 180];
}

/**
 * Draws `scan` top-down into a 2D context of size width × height: the scanner at the centre facing up
 * (its x axis up, y to the left), rings every metre (or 0.5 / 2 / 5 m to keep 2 to 10 rings), the
 * angle range as two rays, each return as a dot. The scale fits `reach` metres (default: the farthest
 * return, at least 1 m) to the nearer edge; a caller that keeps the returned reach and passes it back
 * gets a view that only ever zooms out, never jumps from scan to scan.
 * Returns { scale (pixels per metre), reach, points, radius (metres shown to the edge) }.
 */
export function drawScan(g, scan, width, height, { reach: keep = 0, background = "#fff" } = {}) {
  const geo = scanGeometry(scan);
  const pts = scanPoints(scan);
  const reach = Math.max(keep, pts.maxRange * 1.05, 1);
  const cx = width / 2, cy = height / 2;
  const s = (0.95 * Math.min(cx, cy)) / reach;
  g.fillStyle = background;
  g.fillRect(0, 0, width, height);
  // rings
  const radius = Math.min(cx, cy) / s;
  const step = [0.5, 1, 2, 5, 10, 20, 50].find((d) => radius / d <= 10) ?? 100;
  g.strokeStyle = "#ddd";
  g.lineWidth = 1;
  for (let r = step; r <= radius * 1.42; r += step) {
    g.beginPath();
    g.arc(cx, cy, r * s, 0, 2 * Math.PI);
    g.stroke();
  }
  // screen: scanner x up, y left
  const toScreen = (x, y) => [cx - y * s, cy - x * s];
  g.strokeStyle = "#bbb";
  for (const a of [geo.angleMin, geo.angleMax]) {
    const [px, py] = toScreen(Math.cos(a) * radius * 2, Math.sin(a) * radius * 2);
    g.beginPath();
    g.moveTo(cx, cy);
    g.lineTo(px, py);
    g.stroke();
  }
  const range = intensityRange(scan);
  const dot = Math.max(2, Math.min(4, Math.round(width / 200)));
  for (let k = 0; k < pts.n; k++) {
    const [r, gg, b] = pointColor(scan, pts.index[k], range);
    g.fillStyle = `rgb(${r},${gg},${b})`;
    const [px, py] = toScreen(pts.x[k], pts.y[k]);
    g.fillRect(Math.round(px - dot / 2), Math.round(py - dot / 2), dot, dot);  // whole pixels: no blended edges
  }
  // the scanner: a small triangle pointing along x
  g.fillStyle = "#333";
  g.beginPath();
  g.moveTo(cx, cy - 8);
  g.lineTo(cx - 5, cy + 5);
  g.lineTo(cx + 5, cy + 5);
  g.closePath();
  g.fill();
  return { scale: s, reach, points: pts.n, radius };
}

const deg = (a) => `${Number(((a * 180) / Math.PI).toFixed(2))}°`;

/** "541 ranges, -135° to 135° by 0.5°, 0.1 to 30 m" of a scan. */
export function scanText(scan) {
  const g = scanGeometry(scan);
  const range = Number.isFinite(g.rangeMax) ? `, ${Number(g.rangeMin.toFixed(3))} to ${Number(g.rangeMax.toFixed(3))} m` : "";
  return `${g.count} ranges, ${deg(g.angleMin)} to ${deg(g.angleMax)} by ${deg(g.angleIncrement)}${range}`;
}

/**
 * Puts LaserScanPart packets back into whole scans: a part with data_offset 0 starts a scan of
 * data_total_len ranges; parts that follow in order fill it; the scan is given out when it is full.
 * A part out of order drops the scan being filled (counted in `dropped`); parts before any start (a
 * stream joined mid-scan) are counted in `stray`; sizes are bounded by
 * `maxRanges`.
 */
export class ScanAssembler {
  constructor(maxRanges = 1 << 20) { this.maxRanges = maxRanges; this.scan = null; this.filled = 0; this.dropped = 0; this.stray = 0; }

  /** The whole scan this part completes ({scan_info, ranges, intensities}), or null. */
  push(part) {
    const offset = Number(part?.data_offset), total = Number(part?.data_total_len);
    const n = part?.ranges?.length ?? 0;
    if (!Number.isInteger(offset) || !Number.isInteger(total) || total <= 0 || total > this.maxRanges || offset + n > total) {
      this.dropped++;
      this.scan = null;
      return null;
    }
    if (offset === 0) {
      if (this.scan) this.dropped++;
      const withIntensities = part.intensities?.length === n;
      this.scan = { scan_info: part.scan_info, ranges: new Float64Array(total), intensities: withIntensities ? new Float64Array(total) : null };
      this.filled = 0;
    }
    if (!this.scan) {
      // a part with no scan begun: the stream joined mid-scan, or a scan already dropped
      this.stray++;
      return null;
    }
    if (offset !== this.filled) {
      this.dropped++;
      this.scan = null;
      return null;
    }
    this.scan.ranges.set(part.ranges, offset);
    if (this.scan.intensities) {
      if (part.intensities?.length === n) this.scan.intensities.set(part.intensities, offset);
      else this.scan.intensities = null;
    }
    this.filled += n;
    if (this.filled < total) return null;
    const whole = this.scan;
    this.scan = null;
    if (!whole.intensities) whole.intensities = [];
    return whole;
  }
}

/** "ranges 0 to 179 of 541" of a LaserScanPart. */
function partText(p) {
  const n = p?.ranges?.length ?? 0, o = Number(p?.data_offset);
  return `ranges ${o} to ${o + n - 1} of ${Number(p?.data_total_len)}`;
}

const PICTURE = 320;

/** The scan as an RGBA picture (a FrameView draws it wherever a LaserScan value appears); needs OffscreenCanvas. */
function scanImage(scan) {
  if (typeof OffscreenCanvas === "undefined") return { ok: false, error: { code: "no_canvas", message: "no OffscreenCanvas to draw the scan" } };
  if (!scan?.ranges || typeof scan.ranges.length !== "number") return { ok: false, error: { code: "no_ranges", message: "the scan has no ranges" } };
  const c = new OffscreenCanvas(PICTURE, PICTURE);
  const g = c.getContext("2d");
  drawScan(g, scan, PICTURE, PICTURE);
  return { ok: true, width: PICTURE, height: PICTURE, data: g.getImageData(0, 0, PICTURE, PICTURE).data, encoding: "laser scan" };
}

const INFO = {
  data_header: "com.robotraconteur.sensordata.SensorDataHeader",
  angle_min: ["double", "single"], angle_max: ["double", "single"], angle_increment: ["double", "single"],
  range_min: ["double", "single"], range_max: ["double", "single"],
};
const scanLayout = (info, num) => ({ scan_info: `${L}.${info}`, ranges: `${num}[]`, intensities: `${num}[]` });

export const renderers = [
  { type: `${L}.LaserScanInfo`, layout: INFO },
  { type: `${L}.LaserScanInfof`, layout: INFO },
  { type: `${L}.LaserScan`, layout: scanLayout("LaserScanInfo", "double"), text: scanText, image: scanImage },
  { type: `${L}.LaserScanf`, layout: scanLayout("LaserScanInfof", "single"), text: scanText, image: scanImage },
  { type: `${L}.LaserScanPart`, layout: { ...scanLayout("LaserScanInfo", "double"), data_offset: "uint32", data_total_len: "uint32" }, text: partText },
  { type: `${L}.LaserScanPartf`, layout: { ...scanLayout("LaserScanInfof", "single"), data_offset: "uint32", data_total_len: "uint32" }, text: partText },
];
