// The GPS panel, for com.robotraconteur.gps.GpsSensor: the gps_state wire's position (latitude and
// longitude in degrees, altitude in metres), the fix (status_code by name) and satellites, accuracy
// (err_horz, err in metres), speed (m/s), track (°), and the track drawn in metres east and north of
// the first fix (no map: the numbers and the track). The sensor panel beside it shows sensor_info.

import { h } from "../dom.js";
import { fieldText } from "../std/typed_text.js";
import { GpsTrack } from "../sensor/imu_gps.js";
import { axisText } from "../sensor/sensor_source.js";
import { stateWirePanel } from "./panel_parts.js";

const SIZE = 240;

/** Draws the track's points (metres east, north) into `g`, the newest as a larger dot; returns metres per pixel. */
export function drawTrack(g, points, size = SIZE) {
  g.fillStyle = "#fff";
  g.fillRect(0, 0, size, size);
  if (!points.length) return 0;
  let reach = 5;
  for (const p of points) reach = Math.max(reach, Math.abs(p.east), Math.abs(p.north));
  const s = (0.45 * size) / reach, c = size / 2;
  g.strokeStyle = "#eee";
  g.beginPath(); g.moveTo(c, 0); g.lineTo(c, size); g.moveTo(0, c); g.lineTo(size, c); g.stroke();
  g.strokeStyle = "#1f77b4";
  g.lineWidth = 2;
  g.beginPath();
  points.forEach((p, i) => (i ? g.lineTo(c + p.east * s, c - p.north * s) : g.moveTo(c + p.east * s, c - p.north * s)));
  g.stroke();
  const last = points[points.length - 1];
  g.fillStyle = "#d62728";
  g.beginPath(); g.arc(c + last.east * s, c - last.north * s, 4, 0, 2 * Math.PI); g.fill();
  g.fillStyle = "#555"; g.font = "11px sans-serif"; g.fillText(`N ↑  ${axisText(reach)} m to the edge`, 4, 12);
  return 1 / s;
}

const num = (v, unit) => (typeof v === "number" && Number.isFinite(v) ? `${axisText(v)}${unit}` : "—");
const deg = (v) => (typeof v === "number" && Number.isFinite(v) ? `${Number(v.toFixed(7))}°` : "—");

export function createGpsPanel(parent, ctx) {
  const { view } = ctx;
  return stateWirePanel(parent, ctx, {
    panel: "gps", title: "GPS", wire: "gps_state", typeName: "com.robotraconteur.gps.GpsState",
    fields: ["latitude_deg", "longitude_deg", "altitude"],
    canvasClass: "gps-track", canvasLabel: "track", size: SIZE,
    setup({ type: t, row, canvas, el }) {
      const out = Object.fromEntries(["latitude", "longitude", "altitude", "fix", "satellites", "horizontal error", "error", "speed", "track"].map((k) => [k, row(k)]));
      const statusType = t.fields.find((f) => f.name === "status")?.type;
      const codeField = statusType?.fields?.find((f) => f.name === "status_code");
      const track = new GpsTrack();
      const g = canvas.getContext("2d");
      return {
        received(v) { track.push(Number(v?.latitude_deg), Number(v?.longitude_deg)); return v; },
        draw(s) {
          out.latitude.textContent = deg(s.latitude_deg);
          out.longitude.textContent = deg(s.longitude_deg);
          out.altitude.textContent = num(s.altitude, " m");
          out.fix.textContent = s.status && codeField ? fieldText(s.status, codeField, statusType, view?.text) : "—";
          out.satellites.textContent = s.status ? `${s.status.satellites_used ?? "?"} used of ${s.status.satellites_visible ?? "?"} visible` : "—";
          out["horizontal error"].textContent = num(s.err_horz, " m");
          out.error.textContent = num(s.err, " m");
          out.speed.textContent = num(s.speed, " m/s");
          out.track.textContent = num(s.track_deg, "°");
          el.dataset.metresPerPixel = String(drawTrack(g, track.points()));
        },
      };
    },
  });
}

export const gpsPanel = { name: "gps", order: 15, types: ["com.robotraconteur.gps.GpsSensor"], create: createGpsPanel };
