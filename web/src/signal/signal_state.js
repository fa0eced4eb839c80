// The signal panel's pure logic (panels/signal_panel.js): com.robotraconteur.signal values as a person
// reads and sets them. A signal's value comes as a varvalue (signal_value) or a double[]
// (signal_value_vec); a command goes out as a double[] (signal_command_vec) or a double[] varvalue
// (signal_command). Digital signals read as on / off; others as numbers with their units.

import { enumName } from "../std/enums.js";
import { siUnitText } from "../std/units.js";
import { shortNumber } from "../std/geometry.js";

/** At most this many signals are opened per group, and groups per device (each is a wire subscription). */
export const MAX_SIGNALS = 64;
export const MAX_GROUPS = 16;

/** The numbers of a signal value: a varvalue ({type, value}), a typed array or a number; null for anything else. */
export function signalNumbers(v) {
  if (v === null || v === undefined) return null;
  if (typeof v === "number" || typeof v === "boolean") return [Number(v)];
  if (ArrayBuffer.isView(v) || Array.isArray(v)) {
    return Array.from(v, (x) => Number(x));
  }
  if (typeof v === "object" && "value" in v && typeof v.type === "string") {
    if (v.type === "string") return null;
    return signalNumbers(v.value);
  }
  return null;
}

/** What a SignalInfo says about how to show and set the signal. `enums`: { type (SignalType), access (SignalAccessLevel) }. */
export function signalKind(info, enums) {
  const type = enumName(enums.type, info?.signal_type) ?? "unknown";
  const access = enumName(enums.access, info?.access_level) ?? "undefined";
  const units = Array.from(info?.units ?? [], siUnitText).filter(Boolean);
  const num = (v) => { const n = signalNumbers(v); return n && n.length === 1 && Number.isFinite(n[0]) ? n[0] : null; };
  return {
    name: info?.signal_identifier?.name || "",
    type,
    access,
    digital: type === "digital",
    // the standard's levels below "all" (readonly, restricted, internal, undefined) are not set from a page
    writable: access === "all",
    units,
    min: num(info?.min_value),
    max: num(info?.max_value),
    description: typeof info?.user_description === "string" ? info.user_description : "",
  };
}

/** "on" / "off" for a digital signal, else "12.5 °C" (numbers with the signal's units, one per value or one for all). */
export function signalText(value, kind) {
  const n = signalNumbers(value);
  if (n === null) {
    if (value && typeof value === "object" && value.type === "string") return JSON.stringify(value.value);
    return value === null || value === undefined ? "" : "(not a number)";
  }
  if (kind.digital && n.length === 1) return n[0] !== 0 ? "on" : "off";
  const unitOf = (i) => (kind.units.length === n.length ? kind.units[i] : kind.units.length === 1 ? kind.units[0] : "");
  return n.map((x, i) => `${shortNumber(x, 4)}${unitOf(i) ? ` ${unitOf(i)}` : ""}`).join(", ");
}

/**
 * The double[] command for input `text` (a number) or a switch (`on`: boolean) of signal `kind`;
 * throws Error with what is wrong (not a number, outside min … max) before anything is sent.
 */
export function signalCommand(kind, input) {
  if (typeof input === "boolean") return Float64Array.of(input ? 1 : 0);
  const s = String(input).trim();
  const v = s === "" ? NaN : Number(s);
  if (!Number.isFinite(v)) throw new Error(`${kind.name || "signal"}: enter a number`);
  if (kind.min !== null && v < kind.min) throw new Error(`${kind.name}: ${v} is below its minimum ${kind.min}`);
  if (kind.max !== null && v > kind.max) throw new Error(`${kind.name}: ${v} is above its maximum ${kind.max}`);
  return Float64Array.of(v);
}
