// The tool panel's pure logic (panels/tool_panel.js): a ToolState and ToolInfo of
// com.robotraconteur.robotics.tool as an operator reads them. Positions and commands are in metres
// (the SI unit a gripper's stroke is given in; the robdef names none) and shown in millimetres.

import { enumName, flagNames } from "../std/enums.js";
import { shortNumber } from "../std/geometry.js";

const BAD = new Set(["error", "fatal_error", "estop", "communication_failure", "missed"]);
const GOOD = new Set(["enabled", "ready", "homed", "gripping"]);
const WARN = new Set(["actuating", "homing", "requires_homing"]);

/** The tone of a ToolStateFlags name: "bad", "good", "warn" or "info" (opened, closed, between, …). */
export function toolFlagTone(name) {
  if (BAD.has(name)) return "bad";
  if (GOOD.has(name)) return "good";
  if (WARN.has(name)) return "warn";
  return "info";
}

/** Chips [{ name, tone }] of a tool_state_flags value with the device's ToolStateFlags values. */
export function toolFlagChips(values, n) {
  return flagNames(values, n ?? 0).map((name) => ({ name, tone: toolFlagTone(name) }));
}

/** "42.5 mm" of a position in metres; "" for a value that is no finite number. */
export function mmText(m) {
  const v = Number(m);
  return Number.isFinite(v) ? `${shortNumber(v * 1000, 2)} mm` : "";
}

/**
 * How open the tool is, 0 (closed) to 1 (open), from its position and the info's close_position and
 * open_position (either order); null when they give no range.
 */
export function openFraction(position, info) {
  const c = Number(info?.close_position), o = Number(info?.open_position), p = Number(position);
  if (![c, o, p].every(Number.isFinite) || c === o) return null;
  return Math.min(1, Math.max(0, (p - c) / (o - c)));
}

/** The command range [min, max] (metres) of a ToolInfo, or null when it gives none. */
export function commandRange(info) {
  const lo = Number(info?.command_min), hi = Number(info?.command_max);
  return Number.isFinite(lo) && Number.isFinite(hi) && hi > lo ? [lo, hi] : null;
}

/** The sensor values of a ToolState as rows [{ label, text }] named and unit-labelled from the ToolInfo. */
export function sensorRows(state, info, sensorTypes = []) {
  const values = state?.sensor ? Array.from(state.sensor) : [];
  const types = info?.sensor_type ? Array.from(info.sensor_type) : [];
  const units = info?.sensor_units ? Array.from(info.sensor_units) : [];
  return values.map((v, i) => {
    const name = types[i] !== undefined ? enumName(sensorTypes, types[i]) ?? `sensor ${i}` : `sensor ${i}`;
    const unit = units[i]?.display_units || "";
    return { label: name, text: `${shortNumber(Number(v), 3)}${unit ? ` ${unit}` : ""}` };
  });
}

/**
 * Rows [{ key, label, text }] of a ToolInfo: type, capabilities, stroke, command range, actuation time,
 * sensors. `enums`: { type (ToolTypeCode), cap (ToolCapabilities), sensor (SensorTypeCode) } values.
 */
export function toolInfoRows(info, enums) {
  if (!info || typeof info !== "object") return [];
  const rows = [];
  const add = (key, label, text) => { if (text) rows.push({ key, label, text }); };
  add("tool_type", "type", info.tool_type !== undefined ? enumName(enums.type, info.tool_type) ?? String(info.tool_type) : "");
  add("tool_capabilities", "capabilities", info.tool_capabilities !== undefined ? (flagNames(enums.cap, info.tool_capabilities).join(" | ") || "none") : "");
  if (Number.isFinite(Number(info.close_position)) && Number.isFinite(Number(info.open_position)) && info.close_position !== info.open_position) {
    add("stroke", "closed / open", `${mmText(info.close_position)} / ${mmText(info.open_position)}`);
  }
  const range = commandRange(info);
  if (range) add("command_range", "command range", `${mmText(range[0])} to ${mmText(range[1])}`);
  const t = Number(info.actuation_time);
  if (Number.isFinite(t) && t > 0) add("actuation_time", "actuation time", `${shortNumber(t, 3)} s`);
  const types = info.sensor_type ? Array.from(info.sensor_type) : [];
  const units = info.sensor_units ? Array.from(info.sensor_units) : [];
  const min = info.sensor_min ? Array.from(info.sensor_min) : [], max = info.sensor_max ? Array.from(info.sensor_max) : [];
  add("sensors", "sensors", types.map((c, i) => {
    const unit = units[i]?.display_units ? ` ${units[i].display_units}` : "";
    const span = Number.isFinite(min[i]) && Number.isFinite(max[i]) ? ` ${shortNumber(min[i], 3)} to ${shortNumber(max[i], 3)}${unit}` : unit;
    return `${enumName(enums.sensor, c) ?? c}${span}`;
  }).join(", "));
  return rows;
}

/**
 * Hold-to-run for a tool: a motion call (open(), close(), setf_command(x), home()) starts when a control
 * is pressed, and every way the hold ends calls halt(), after the motion call's answer (so the halt can
 * never overtake it); a new motion call waits for the halt of the hold before. A refused motion call ends
 * the hold without a halt (nothing moves).
 * `halt()` returns a promise; `onError(error, what)`; `onStop(reason)` when a hold ends.
 */
export class ToolHold {
  constructor({ halt, onError = () => {}, onStop = () => {} }) {
    this.halt = halt;
    this.onError = onError;
    this.onStop = onStop;
    this.current = null;  // { name, started: Promise<boolean> } while held
    this.halting = Promise.resolve();  // settles once the last hold's halt() was answered
    this.halts = 0;       // halt() calls made (for tests)
  }

  get active() { return this.current !== null; }

  /** Starts holding motion `name` by calling `call()`; a hold already on is ended first. */
  start(name, call) {
    // the halt of a hold before is sent first: sent after, it would stop this new motion
    const before = this.current ? this.stop("replaced") : this.halting;
    const hold = { name };
    hold.started = before.then(call).then(() => true, (e) => {
      if (this.current === hold) { this.current = null; this.onStop("refused"); }
      this.onError(e, name);
      return false;
    });
    this.current = hold;
    return hold.started;
  }

  /** Ends the hold (if any): halt() once its motion call was answered and accepted. Resolves when sent. */
  stop(reason) {
    const hold = this.current;
    if (!hold) return Promise.resolve();
    this.current = null;
    this.onStop(reason);
    this.halting = hold.started.then((moving) => {
      if (!moving) return undefined;
      this.halts++;
      return Promise.resolve().then(() => this.halt()).catch((e) => this.onError(e, "halt"));
    });
    return this.halting;
  }
}
