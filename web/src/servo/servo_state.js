// The servo and actuator panels' pure logic (panels/servo_panel.js, actuator_panel.js):
// com.robotraconteur.servo ServoState / ServoInfo and com.robotraconteur.actuator ActuatorState /
// ActuatorInfo as an operator reads them, and the commands a held jog streams.

import { enumName } from "../std/enums.js";
import { siUnitText } from "../std/units.js";
import { shortNumber } from "../std/geometry.js";

/** Short unit text of a JointPositionUnits / JointEffortUnits name ("radian" → "rad"); "" for implicit. */
const UNIT_TEXT = { meter: "m", radian: "rad", degree: "°", ticks_lin: "ticks", ticks_rot: "ticks", nanoticks_lin: "nanoticks", nanoticks_rot: "nanoticks",
  newton: "N", newton_meter: "N·m", ampere: "A", volt: "V", pascal: "Pa", coulomb: "C", tesla: "T", weber: "Wb",
  meter_second2: "m/s²", radian_second2: "rad/s²", degree_second2: "°/s²" };
export function unitText(enumValues, code) {
  const name = enumName(enumValues, code);
  return !name || name === "implicit" ? "" : UNIT_TEXT[name] ?? name;
}

/** How many axes a servo has: servo_info.axis_count, else the length of the state's position. */
export function axisCount(info, state) {
  const n = Number(info?.axis_count);
  if (Number.isInteger(n) && n > 0) return Math.min(n, 64);
  return Math.min(state?.position?.length ?? 0, 64);
}

const num = (a, i) => { const v = Number(a?.[i]); return Number.isFinite(v) ? v : null; };
const withUnit = (v, u, digits = 4) => (v === null ? "" : `${shortNumber(v, digits)}${u ? ` ${u}` : ""}`);

/**
 * Rows [{ axis, position, velocity, effort, command }] (texts) of a ServoState with the units of its
 * ServoInfo (`enums`: { position (JointPositionUnits), effort (JointEffortUnits) } values). Velocity is
 * in the position's unit per second.
 */
export function servoAxisRows(state, info, enums) {
  const n = axisCount(info, state);
  const pu = Array.from(info?.position_units ?? []), eu = Array.from(info?.effort_units ?? []);
  const rows = [];
  for (let i = 0; i < n; i++) {
    const p = unitText(enums.position, pu[i] ?? pu[0]), e = unitText(enums.effort, eu[i] ?? eu[0]);
    const command = num(state?.position_command, i) ?? null;
    rows.push({
      axis: i,
      position: withUnit(num(state?.position, i), p),
      velocity: withUnit(num(state?.velocity, i), p ? `${p}/s` : ""),
      effort: withUnit(num(state?.effort, i), e),
      command: command === null ? "" : withUnit(command, p),
      limits: [num(info?.position_min, i), num(info?.position_max, i)],
    });
  }
  return rows;
}

/**
 * The velocity command of a held jog: axis `axis` at `direction` (±1) × `fraction` of its
 * velocity_max, the other axes 0. Throws Error when the servo gives no usable velocity limit.
 */
export function jogVelocities(info, axis, direction, fraction, count) {
  const max = num(info?.velocity_max, axis);
  if (max === null || max <= 0) throw new Error(`axis ${axis}: servo_info gives no velocity_max to jog at`);
  const f = Math.max(0, Math.min(1, Number(fraction)));
  const v = new Float64Array(count);
  v[axis] = Math.sign(direction) * f * max;
  return v;
}

/** A ServoCommand value: seqno and status_seqno as BigInt (uint64), the command values. */
export function servoCommand(seqno, statusSeqno, command) {
  return { seqno: BigInt(seqno), status_seqno: BigInt(statusSeqno ?? 0), command: Float64Array.from(command) };
}

/** Rows [{ key, label, text }] of an ActuatorState's commands with the info's command_units. */
export function actuatorRows(state, info) {
  const units = Array.from(info?.command_units ?? [], siUnitText);
  return Array.from(state?.actuator_command ?? []).map((v, i) => ({
    key: `command-${i}`, label: `command ${i}`, text: withUnit(Number(v), units[i] ?? (units.length === 1 ? units[0] : "")),
  }));
}

/**
 * The command a held "Run" streams for an actuator with one command value: `text` as a number, checked
 * to be finite. Throws Error otherwise.
 */
export function actuatorCommand(text, count = 1) {
  const s = String(text).trim();
  const v = s === "" ? NaN : Number(s);
  if (!Number.isFinite(v)) throw new Error("enter a number to command");
  return Float64Array.from({ length: Math.max(1, count) }, () => v);
}
