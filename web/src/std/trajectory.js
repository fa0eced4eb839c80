// com.robotraconteur.robotics.trajectory.JointTrajectory (joint names, position units, waypoints with
// joint_position and time_from_start) as text and as a plot: one line per joint, position over time,
// drawn wherever such a value appears (a function's result, a property, a recording's replay).
// Radians are plotted in degrees, as the robot panel shows joints.

const T = "com.robotraconteur.robotics.trajectory";
const J = "com.robotraconteur.robotics.joints";
const COLORS = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf"];
/** Waypoints and joints drawn at most (a longer trajectory is cut, and says so). */
export const MAX_WAYPOINTS = 100000;
export const MAX_JOINTS = 32;

const unitName = (enumValues, code) => enumValues?.find((e) => e.value === Number(code))?.name ?? null;

/**
 * { names, times, series (one Float64Array per joint), units (names), unitText, cut } of a JointTrajectory,
 * positions converted to degrees for joints in radians. `unitEnum`: JointPositionUnits values (null:
 * radians assumed for all, the robdef's default for revolute joints). Null for a value without waypoints.
 */
export function trajectorySeries(traj, unitEnum = null) {
  const wps = Array.from(traj?.waypoints ?? []);
  if (!wps.length) return null;
  const n = Math.min(MAX_WAYPOINTS, wps.length);
  const joints = Math.min(MAX_JOINTS, Math.max(...wps.slice(0, n).map((w) => w?.joint_position?.length ?? 0)));
  const names = Array.from({ length: joints }, (_, i) => traj?.joint_names?.[i] || `joint_${i}`);
  const units = Array.from({ length: joints }, (_, i) => unitName(unitEnum, traj?.joint_units?.[i]) ?? (unitEnum ? "implicit" : "radian"));
  const times = new Float64Array(n);
  const series = names.map(() => new Float64Array(n));
  for (let k = 0; k < n; k++) {
    times[k] = Number(wps[k]?.time_from_start ?? k);
    for (let i = 0; i < joints; i++) {
      const v = Number(wps[k]?.joint_position?.[i]);
      series[i][k] = units[i] === "radian" ? v * 180 / Math.PI : v;
    }
  }
  const shown = units.map((u) => (u === "radian" || u === "degree" ? "°" : u === "meter" ? "m" : ""));
  return { names, times, series, units, unitText: shown, cut: wps.length > n };
}

/** "3 joints, 5 waypoints over 4.2 s (shoulder, elbow, wrist)". */
export function trajectoryText(traj, ctx) {
  const s = trajectorySeries(traj, ctx?.outline?.types?.get(`${J}.JointPositionUnits`)?.values ?? null);
  if (!s) return "joint trajectory without waypoints";
  const span = s.times.length ? s.times[s.times.length - 1] - s.times[0] : 0;
  return `${s.names.length} joints, ${traj.waypoints.length} waypoints over ${Number(span.toFixed(3))} s (${s.names.join(", ")})${s.cut ? `, first ${MAX_WAYPOINTS} drawn` : ""}`;
}

/**
 * Draws the plot into a 2D context: axes, one line per joint (its colour in COLORS order), the names
 * with their units as a legend. Returns { min, max, t0, t1 } of what was drawn, or null.
 */
export function drawTrajectory(g, s, width, height) {
  g.fillStyle = "#fff";
  g.fillRect(0, 0, width, height);
  if (!s) return null;
  const left = 48, right = 8, top = 8, bottom = 22 + 14 * Math.ceil(s.names.length / 4);
  const t0 = s.times[0], t1 = Math.max(s.times[s.times.length - 1], t0 + 1e-9);
  let min = Infinity, max = -Infinity;
  for (const a of s.series) for (const v of a) if (Number.isFinite(v)) { min = Math.min(min, v); max = Math.max(max, v); }
  if (!Number.isFinite(min)) return null;
  if (max - min < 1e-9) { min -= 1; max += 1; }
  const x = (t) => left + (t - t0) / (t1 - t0) * (width - left - right);
  const y = (v) => top + (max - v) / (max - min) * (height - top - bottom);
  g.strokeStyle = "#ccc";
  g.lineWidth = 1;
  g.strokeRect(left, top, width - left - right, height - top - bottom);
  g.fillStyle = "#555";
  g.font = "11px sans-serif";
  g.fillText(String(Number(max.toPrecision(4))), 2, top + 10);
  g.fillText(String(Number(min.toPrecision(4))), 2, height - bottom);
  g.fillText(`${Number(t0.toFixed(3))} s`, left, height - bottom + 12);
  const end = `${Number(t1.toFixed(3))} s`;
  g.fillText(end, width - right - g.measureText(end).width, height - bottom + 12);
  s.series.forEach((a, i) => {
    g.strokeStyle = COLORS[i % COLORS.length];
    g.lineWidth = 2;
    g.beginPath();
    a.forEach((v, k) => { if (k === 0) g.moveTo(x(s.times[k]), y(v)); else g.lineTo(x(s.times[k]), y(v)); });
    g.stroke();
    const lx = left + (i % 4) * ((width - left) / 4), ly = height - bottom + 26 + 14 * Math.floor(i / 4);
    g.fillStyle = COLORS[i % COLORS.length];
    g.fillText(`${s.names[i]}${s.unitText[i] ? ` (${s.unitText[i]})` : ""}`, lx, ly);
  });
  return { min, max, t0, t1 };
}

const WIDTH = 480, HEIGHT = 260;

function trajectoryImage(traj, ctx) {
  if (typeof OffscreenCanvas === "undefined") return { ok: false, error: { code: "no_canvas", message: "no OffscreenCanvas to draw the trajectory" } };
  const s = trajectorySeries(traj, ctx?.outline?.types?.get(`${J}.JointPositionUnits`)?.values ?? null);
  if (!s) return { ok: false, error: { code: "no_waypoints", message: "the trajectory has no waypoints" } };
  const c = new OffscreenCanvas(WIDTH, HEIGHT);
  const g = c.getContext("2d");
  drawTrajectory(g, s, WIDTH, HEIGHT);
  return { ok: true, width: WIDTH, height: HEIGHT, data: g.getImageData(0, 0, WIDTH, HEIGHT).data, encoding: "joint trajectory" };
}

export const renderers = [
  {
    type: `${T}.JointTrajectory`,
    layout: { joint_names: "string{list}", joint_units: `${J}.JointPositionUnits{list}`, waypoints: `${T}.JointTrajectoryWaypoint{list}` },
    text: trajectoryText,
    image: trajectoryImage,
  },
  { type: `${T}.JointTrajectoryWaypoint`, layout: { joint_position: "double[]", time_from_start: "double" } },
];
