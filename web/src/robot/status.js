// The robot's state for an operator: the enums of a RobotState by name and its robot_state_flags as
// chips, each with a tone the style sheet colours (good, bad, warn, info), and whether the state is
// stale (no robot_state for a while).

import { enumName, flagNames } from "../std/enums.js";

/** No robot_state for this long (ms): the panel marks what it shows as stale. */
export const STALE_MS = 1000;

const BAD = /^(error|fatal_error|estop|communication_failure)/;
const GOOD = new Set(["ready", "enabled", "homed", "enabling_switch", "estop_released", "valid_position_command", "valid_velocity_command"]);
const WARN = new Set(["homing_required", "trajectory_running"]);

/** The tone of a flag name: "bad" (errors, e-stops, communication failure), "good", "warn" or "info". */
export function flagTone(name) {
  if (name === "estop_released") return "good";
  if (BAD.test(name)) return "bad";
  if (GOOD.has(name)) return "good";
  if (WARN.has(name)) return "warn";
  return "info";
}

/** Chips [{ name, tone }] of flags value `n` (number or BigInt) with enum values `values`; none set: []. */
export function flagChips(values, n) {
  return flagNames(values, n).map((name) => ({ name, tone: flagTone(name) }));
}

/** "jog" for an enum value with a name, "7 (unknown)" otherwise, "" for undefined. */
export function modeText(values, n) {
  if (n === undefined || n === null) return "";
  return enumName(values, n) ?? `${n} (unknown)`;
}

/** True when the last state came more than STALE_MS before `now` (ms; never: true). */
export function isStale(lastMs, nowMs, staleMs = STALE_MS) {
  return !(lastMs > 0) || nowMs - lastMs > staleMs;
}

/** Names of the flags set in a RobotCapabilities value (a Set), for what the panel offers. */
export function capabilitySet(values, n) {
  return new Set(flagNames(values, n ?? 0));
}
