// Enum values by name, and bit-flag fields by the names of their set flags. Both use the enum values
// of the device's own definitions ([{name, value}] as robdef_outline.js reads them).
//
// Flag fields are integers in the definitions (RobotState's `uint64 robot_state_flags`, Camera's
// `uint32 capabilities`); their enum is found by name: the field name in CamelCase
// (robot_state_flags → RobotStateFlags), the owner's name plus Flags or Capabilities (CameraState's
// state_flags → CameraStateFlags, SensorData's data_flags → SensorDataFlags), or the owner's name
// without Info/State/Status plus the same (ServoInfo's capabilities → ServoCapabilities), looked up in
// the owner's service, its `using` names and its imports. An enum counts as flags only when every
// nonzero value is a power of two. GpsStatus names its enum otherwise (FLAG_ENUMS).

import { findNamed } from "./describe.js";
import { parseType } from "./rr_types.js";

/** Flag fields whose enum the naming rule does not find: "<owner qualified>.<field>" → enum name. */
export const FLAG_ENUMS = Object.freeze({
  "com.robotraconteur.gps.GpsStatus.motion_source_flags": "GpsMeasureSourceFlags",
  "com.robotraconteur.gps.GpsStatus.orientation_source_flags": "GpsMeasureSourceFlags",
  "com.robotraconteur.gps.GpsStatus.position_source_flags": "GpsMeasureSourceFlags",
});

/** The name of enum value `n` in `values`, or null. */
export function enumName(values, n) {
  const v = Number(n);
  return values?.find((e) => e.value === v)?.name ?? null;
}

/** "name" of an enum value; "7 (not a value of the enum)" when it has none. */
export function formatEnum(values, n) {
  return enumName(values, n) ?? `${n} (not a value of the enum)`;
}

/** True when every nonzero value of the enum is a power of two (and there are at least two). */
export function isFlagEnum(values) {
  const bits = (values || []).filter((e) => e.value !== 0);
  return bits.length >= 2 && bits.every((e) => e.value > 0 && Number.isInteger(Math.log2(e.value)));
}

/**
 * Names of the flags set in `n` (number or BigInt), in the enum's order; bits the enum does not name
 * as "0x…" at the end.
 */
export function flagNames(values, n) {
  let rest;
  try { rest = BigInt(n); } catch { return []; }
  const names = [];
  for (const e of values || []) {
    const bit = BigInt(e.value);
    if (bit > 0n && (rest & bit) === bit) { names.push(e.name); rest &= ~bit; }
  }
  if (rest !== 0n) names.push(`0x${(rest < 0n ? BigInt.asUintN(64, rest) : rest).toString(16)}`);
  return names;
}

/** "enabled | ready | homed", or "none" when no flag is set. */
export function formatFlags(values, n) {
  const names = flagNames(values, n);
  return names.length ? names.join(" | ") : "none";
}

const camel = (s) => s.split("_").filter(Boolean).map((w) => w[0].toUpperCase() + w.slice(1)).join("");

const INTEGER = /^u?int(8|16|32|64)$/;
/** The parts ({base, array, dims, container}) of a field's type: its descriptor (from TypeDescriber), else its text split. */
const partsOf = (field) => field?.descriptor ?? parseType(field?.type);

/**
 * The enum values of flag field `field` ({name, type, descriptor?}) of `owner` (an outline entry:
 * structure or object), or null when it is not a flag field or its enum is not found.
 */
export function flagEnumFor(outline, owner, field) {
  const name = field?.name || "";
  const suffix = /flags$/.test(name) ? "Flags" : /capabilities$/.test(name) ? "Capabilities" : null;
  const t = partsOf(field);
  if (!suffix || t.array || t.container || !INTEGER.test(t.base)) return null;
  const ownerName = owner?.name || "";
  const candidates = [
    FLAG_ENUMS[`${owner?.qualified}.${name}`], camel(name), `${ownerName}${suffix}`,
    `${ownerName.replace(/(Info|State|Status)$/, "")}${suffix}`,
  ];
  for (const c of candidates) {
    if (!c) continue;
    const t = findNamed(outline, c, owner.service);
    if (t?.kind === "enum" && isFlagEnum(t.values)) return t.values;
  }
  return null;
}

/** Field annotator for TypeDescriber: { flags: enum values } on flag fields. */
export function flagAnnotator(owner, field, outline) {
  const flags = flagEnumFor(outline, owner, field);
  return flags ? { flags } : null;
}

/**
 * The enum values of integer code field `field` of `owner`, for fields that hold enum values without
 * being typed as the enum: AdvancedRobotState's `uint8[] joint_position_units` holds
 * JointPositionUnits values, `joint_effort_units` JointEffortUnits ones. Found as flag enums are (the
 * field name in CamelCase); only for names ending in `_units` and for enums that are not flags.
 */
export function codeEnumFor(outline, owner, field) {
  const name = field?.name || "";
  const p = partsOf(field);
  const scalarOrVector = !p.container && (!p.array || (p.array === "vector" && !p.dims));
  if (!/_units$/.test(name) || !scalarOrVector || !INTEGER.test(p.base)) return null;
  const t = findNamed(outline, camel(name), owner?.service);
  return t?.kind === "enum" && !isFlagEnum(t.values) ? t.values : null;
}

/** Field annotator for TypeDescriber: { codes: enum values } on integer fields holding enum codes. */
export function codeAnnotator(owner, field, outline) {
  const codes = codeEnumFor(outline, owner, field);
  return codes ? { codes } : null;
}

/** "radian" for one code, "[radian, radian, meter]" for an array of codes. */
export function formatCodes(values, v) {
  if (typeof v === "number" || typeof v === "bigint") return formatEnum(values, v);
  return `[${Array.from(v, (x) => formatEnum(values, x)).join(", ")}]`;
}
