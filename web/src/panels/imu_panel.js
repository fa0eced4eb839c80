// The IMU panel, for com.robotraconteur.imu.ImuSensor: the imu_state wire's orientation as a gizmo
// (the sensor's x, y, z axes in red, green, blue, seen from a fixed viewpoint over a grey world triad)
// and as roll, pitch, yaw, its angular velocity in rad/s and linear acceleration in m/s² (the
// geometry definitions' SI units). The sensor panel beside it shows sensor_info and the parameters.

import { h } from "../dom.js";
import { formatRotation, namedFields, shortNumber } from "../std/geometry.js";
import { gizmoAxes } from "../sensor/imu_gps.js";
import { stateWirePanel } from "./panel_parts.js";

const SIZE = 200;
const COLORS = { x: "#d62728", y: "#2ca02c", z: "#1f77b4" };
const vec = (v) => { const p = namedFields(v, ["x", "y", "z"]); return p ? `(${["x", "y", "z"].map((k) => shortNumber(p[k], 4)).join(", ")})` : "?"; };

/** Draws the orientation gizmo of quaternion `q` (and the grey world axes) into context `g`. */
export function drawGizmo(g, q, size = SIZE) {
  const c = size / 2, len = size * 0.38;
  g.fillStyle = "#fff";
  g.fillRect(0, 0, size, size);
  const arrows = (axes, style, width) => {
    for (const a of axes) {
      g.strokeStyle = style(a);
      g.lineWidth = width;
      g.beginPath();
      g.moveTo(c, c);
      g.lineTo(c + a.dx * len, c + a.dy * len);
      g.stroke();
    }
  };
  arrows(gizmoAxes({ w: 1, x: 0, y: 0, z: 0 }), () => "#ccc", 1);
  const axes = gizmoAxes(q);
  if (!axes) return false;
  arrows(axes, (a) => COLORS[a.axis], 4);
  g.font = "12px sans-serif";
  for (const a of axes) { g.fillStyle = COLORS[a.axis]; g.fillText(a.axis, c + a.dx * (len + 10) - 3, c + a.dy * (len + 10) + 4); }
  return true;
}

export function createImuPanel(parent, ctx) {
  return stateWirePanel(parent, ctx, {
    panel: "imu", title: "IMU", wire: "imu_state", typeName: "com.robotraconteur.imu.ImuState",
    fields: ["orientation", "angular_velocity", "linear_acceleration"],
    canvasClass: "imu-gizmo", canvasLabel: "orientation", size: SIZE,
    setup({ row, canvas }) {
      const out = { orientation: row("orientation"), angular_velocity: row("angular velocity"), linear_acceleration: row("linear acceleration") };
      const g = canvas.getContext("2d");
      return {
        received: (v) => (Array.isArray(v) && v.length === 1 ? v[0] : v),
        draw(s) {
          out.orientation.textContent = formatRotation(s.orientation) ?? "(invalid quaternion)";
          out.angular_velocity.textContent = `${vec(s.angular_velocity)} rad/s`;
          out.linear_acceleration.textContent = `${vec(s.linear_acceleration)} m/s²`;
          drawGizmo(g, s.orientation);
        },
      };
    },
  });
}

export const imuPanel = { name: "imu", order: 15, types: ["com.robotraconteur.imu.ImuSensor"], create: createImuPanel };
