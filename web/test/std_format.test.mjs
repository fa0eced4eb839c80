// Readable text of the standard types (src/std/uuid.js, identifier.js, datetime.js, geometry.js,
// enums.js, units.js): expected outputs written by hand or computed here another way.
import { test } from "node:test";
import assert from "node:assert/strict";
import { RobdefOutline } from "../src/std/robdef_outline.js";
import { formatUuid, isNilUuid } from "../src/std/uuid.js";
import { formatIdentifier } from "../src/std/identifier.js";
import { formatTime, formatDuration, timeParts, isoTime, ageText, timeSeconds } from "../src/std/datetime.js";
import { quaternionToRpy, formatPose, formatTransform, formatRotation } from "../src/std/geometry.js";
import { enumName, formatEnum, flagNames, formatFlags, isFlagEnum } from "../src/std/enums.js";
import { siUnitText, unitsOf, unitsFieldFor } from "../src/std/units.js";
import { standardDescriber } from "../src/std/standard.js";
import { typedText } from "../src/std/typed_text.js";
import { standardDefinitions, SKIP_REASON } from "./std_fixtures.mjs";

const seq = Uint8Array.from({ length: 16 }, (_, i) => i);
const uuidValue = (bytes) => ({ uuid_bytes: bytes });

test("UUID: 8-4-4-4-12 lower-case hex, bytes in order", () => {
  assert.equal(formatUuid(uuidValue(seq)), "00010203-0405-0607-0809-0a0b0c0d0e0f");
  assert.equal(formatUuid(Uint8Array.of(0xff, 0xee, 0xdd, 0xcc, 0xbb, 0xaa, 0x99, 0x88, 0x77, 0x66, 0x55, 0x44, 0x33, 0x22, 0x11, 0)),
    "ffeeddcc-bbaa-9988-7766-554433221100");
  assert.equal(formatUuid(uuidValue(new Uint8Array(15))), null);
  assert.equal(formatUuid({}), null);
  assert.equal(formatUuid(null), null);
  assert.equal(isNilUuid(uuidValue(new Uint8Array(16))), true);
  assert.equal(isNilUuid(uuidValue(seq)), false);
});

test("Identifier: name (uuid); just the name for the zero UUID; just the UUID without a name", () => {
  assert.equal(formatIdentifier({ name: "robot1", uuid: uuidValue(seq) }), "robot1 (00010203-0405-0607-0809-0a0b0c0d0e0f)");
  assert.equal(formatIdentifier({ name: "robot1", uuid: uuidValue(new Uint8Array(16)) }), "robot1");
  assert.equal(formatIdentifier({ name: "", uuid: uuidValue(seq) }), "00010203-0405-0607-0809-0a0b0c0d0e0f");
  assert.equal(formatIdentifier({ name: "", uuid: uuidValue(new Uint8Array(16)) }), "(none)");
  assert.equal(formatIdentifier({ name: "x", uuid: null }), "x");
  assert.equal(formatIdentifier(5), null);
});

const NOON = BigInt(Date.UTC(2024, 4, 1, 12, 0, 0) / 1000);  // 2024-05-01T12:00:00Z

test("times: ISO 8601 with the fraction written, and the age against the page's clock", () => {
  const ts2 = { clock_info: { clock_type: 1, clock_uuid: uuidValue(seq), offset_microseconds: 0n }, seconds: NOON, nanoseconds: 250000000 };
  const now = Number(NOON) * 1000 + 3450;
  assert.equal(formatTime(ts2, { now }), "2024-05-01T12:00:00.25Z (3.2 s ago)");
  assert.equal(formatTime({ microseconds: NOON * 1000000n + 250000n }, { now }), "2024-05-01T12:00:00.25Z (3.2 s ago)");
  assert.equal(formatTime({ microseconds: NOON * 1000000n + 1n }, { now: Number(NOON) * 1000 }), "2024-05-01T12:00:00.000001Z (0 ms ago)");
  assert.equal(formatTime({ ...ts2, nanoseconds: 0 }, { now: now + 120000 }), "2024-05-01T12:00:00Z (2.1 min ago)");
  assert.equal(formatTime({ ...ts2, nanoseconds: 1 }, { now: Number(NOON) * 1000 - 2000 }), "2024-05-01T12:00:00.000000001Z (in 2.0 s)");
  assert.equal(formatTime({ seconds: 0n, nanoseconds: 0, clock_info: { clock_type: 1 } }), "(not set)");
  assert.equal(formatTime({ microseconds: 0n }), "(not set)");
  assert.equal(formatTime({ name: "x" }), null);
  // before the epoch: whole seconds round down, the fraction stays positive
  assert.deepEqual(timeParts({ microseconds: -1n }), { seconds: -1n, nanoseconds: 999999000 });
  assert.equal(isoTime(timeParts({ microseconds: -1n })), "1969-12-31T23:59:59.999999Z");
  assert.equal(timeSeconds({ seconds: 10, nanoseconds: 500000000 }), 10.5);
  assert.equal(isoTime({ seconds: 10n ** 15n, nanoseconds: 0 }), null);  // past Date's years
  assert.equal(ageText(90000), "1.0 d ago");
});

test("DateTimeLocal: local time with its offset and zone; Duration as a length", () => {
  const local = { clock_info: { clock_type: 1 }, seconds: NOON, nanoseconds: 0, utc_offset_seconds: 7200, timezone_name: "Europe/Berlin" };
  assert.equal(formatTime(local, { now: Number(NOON) * 1000 + 500 }), "2024-05-01T14:00:00+02:00 Europe/Berlin (500 ms ago)");
  assert.equal(formatTime({ ...local, utc_offset_seconds: -(5 * 3600 + 1800), timezone_name: "" }, { now: Number(NOON) * 1000 }),
    "2024-05-01T06:30:00-05:30 (0 ms ago)");
  assert.equal(formatDuration({ seconds: 1n, nanoseconds: 500000000 }), "1.5 s");
  assert.equal(formatDuration({ seconds: 0n, nanoseconds: 2500000 }), "3 ms");
});

test("times on clocks the page cannot compare (by the standard ClockTypeCode) show the clock, not an age", (t) => {
  const defs = standardDefinitions();
  if (!defs) return t.skip(SKIP_REASON);
  const clockEnum = new RobdefOutline(defs).enumOf("ClockTypeCode", "com.robotraconteur.datetime");
  const code = (name) => clockEnum.find((e) => e.name === name).value;
  const at = (name) => ({ clock_info: { clock_type: code(name) }, seconds: NOON, nanoseconds: 0 });
  const now = Number(NOON) * 1000 + 1000;
  assert.equal(formatTime(at("sim_clock_scaled"), { now, clockEnum }), "2024-05-01T12:00:00Z (sim_clock_scaled clock)");
  assert.equal(formatTime(at("node_arb_clock"), { now, clockEnum }), "2024-05-01T12:00:00Z (node_arb_clock clock)");
  assert.equal(formatTime(at("aux_3"), { now, clockEnum }), "2024-05-01T12:00:00Z (aux_3 clock)");
  for (const name of ["default", "system_rtc_clock", "node_ntp_clock", "unknown"]) {
    assert.equal(formatTime(at(name), { now, clockEnum }), "2024-05-01T12:00:00Z (1.0 s ago)", name);
  }
});

/** Quaternion {w, x, y, z} of R = Rz(yaw) Ry(pitch) Rx(roll), by multiplying the three axis rotations. */
function quaternionOf(roll, pitch, yaw) {
  const mul = (a, b) => ({
    w: a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z,
    x: a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
    y: a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
    z: a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w,
  });
  const axis = (a, k) => ({ w: Math.cos(a / 2), x: 0, y: 0, z: 0, [k]: Math.sin(a / 2) });
  return mul(mul(axis(yaw, "z"), axis(pitch, "y")), axis(roll, "x"));
}

/** [roll, pitch, yaw] from the rotation matrix of q (another route than the code's). */
function rpyFromMatrix({ w, x, y, z }) {
  const r00 = 1 - 2 * (y * y + z * z), r10 = 2 * (x * y + w * z), r20 = 2 * (x * z - w * y);
  const r21 = 2 * (y * z + w * x), r22 = 1 - 2 * (x * x + y * y);
  return [Math.atan2(r21, r22), Math.atan2(-r20, Math.hypot(r00, r10)), Math.atan2(r10, r00)];
}

test("Pose and Transform: position plus roll-pitch-yaw in degrees (quaternion w first)", () => {
  const deg = Math.PI / 180;
  for (const [r, p, y] of [[0, 0, 0], [10, 20, 30], [-170, 45, 100], [90, -60, -135], [1, 89, 2]]) {
    const q = quaternionOf(r * deg, p * deg, y * deg);
    const got = quaternionToRpy(q);
    const expected = [r * deg, p * deg, y * deg];
    got.forEach((a, i) => assert.ok(Math.abs(a - expected[i]) < 1e-9, `${[r, p, y]}: ${got}`));
    rpyFromMatrix(q).forEach((a, i) => assert.ok(Math.abs(a - got[i]) < 1e-9));
    // not normalised, or negated: the same rotation
    const scaled = quaternionToRpy({ w: -2 * q.w, x: -2 * q.x, y: -2 * q.y, z: -2 * q.z });
    scaled.forEach((a, i) => assert.ok(Math.abs(a - got[i]) < 1e-9));
  }
  // gimbal lock: pitch ±90°, the rest given to yaw
  const lock = quaternionToRpy(quaternionOf(0, Math.PI / 2, 30 * deg));
  assert.ok(Math.abs(lock[1] - Math.PI / 2) < 1e-6 && Math.abs(lock[2] - 30 * deg) < 1e-6 && lock[0] === 0, String(lock));
  assert.equal(quaternionToRpy({ w: 0, x: 0, y: 0, z: 0 }), null);

  const s = Math.SQRT1_2;
  const pose = { orientation: { w: s, x: 0, y: 0, z: s }, position: { x: 0.5, y: -0.25, z: 1 / 3 } };
  assert.equal(formatPose(pose), "position (0.5, -0.25, 0.3333) m, rpy (0, 0, 90)°");
  assert.equal(formatPose(Float64Array.of(s, 0, 0, s, 0.5, -0.25, 1 / 3)), "position (0.5, -0.25, 0.3333) m, rpy (0, 0, 90)°");
  assert.equal(formatTransform({ rotation: quaternionOf(0, 0, -Math.PI / 2), translation: { x: 1, y: 2, z: 3 } }),
    "translation (1, 2, 3) m, rpy (0, 0, -90)°");
  assert.equal(formatRotation(quaternionOf(10 * deg, 20 * deg, 30 * deg)), "rpy (10, 20, 30)°");
  assert.equal(formatPose({ orientation: { w: 0, x: 0, y: 0, z: 0 }, position: { x: 0, y: 0, z: 0 } }), null);
  assert.equal(formatPose({ position: { x: 0, y: 0, z: 0 } }), null);
});

const STATE_FLAGS = [
  { name: "unknown", value: 0 }, { name: "error", value: 1 }, { name: "estop", value: 4 },
  { name: "enabled", value: 0x20000 }, { name: "ready", value: 0x40000 }, { name: "trajectory_running", value: 0x4000000 },
];

test("enums by name; flag words by the names of the set flags", () => {
  const mode = [{ name: "invalid_state", value: -1 }, { name: "halt", value: 0 }, { name: "jog", value: 1 }];
  assert.equal(enumName(mode, -1), "invalid_state");
  assert.equal(formatEnum(mode, 1), "jog");
  assert.equal(formatEnum(mode, 9), "9 (not a value of the enum)");
  assert.equal(isFlagEnum(mode), false);
  assert.equal(isFlagEnum(STATE_FLAGS), true);
  assert.deepEqual(flagNames(STATE_FLAGS, 0x60001), ["error", "enabled", "ready"]);
  assert.equal(formatFlags(STATE_FLAGS, 0x4060000n), "enabled | ready | trajectory_running");  // uint64 as BigInt
  assert.equal(formatFlags(STATE_FLAGS, 0), "none");
  assert.equal(formatFlags(STATE_FLAGS, 0x20000n | (1n << 40n) | 2n), "enabled | 0x10000000002");
  assert.equal(formatFlags(STATE_FLAGS, -1), "error | estop | enabled | ready | trajectory_running | 0xfffffffffbf9fffa");
});

test("units: SIUnit display text; the sibling field that names a field's units", (t) => {
  assert.equal(siUnitText({ display_units: "m/s", encoded_units: "m*s^-1" }), "m/s");
  assert.equal(siUnitText({ display_units: "", encoded_units: "m*s^-1" }), "m*s^-1");
  const owner = { fields: ["data", "data_units", "data_flags", "sensor_min", "sensor_units", "joint_position_command",
    "joint_position_units"].map((name) => ({ name, type: "double[]" })) };
  assert.equal(unitsFieldFor(owner, "data"), "data_units");
  assert.equal(unitsFieldFor(owner, "data_flags"), null);
  assert.equal(unitsFieldFor(owner, "sensor_min"), "sensor_units");
  assert.equal(unitsFieldFor(owner, "joint_position_command"), "joint_position_units");
  assert.equal(unitsFieldFor(owner, "data_units"), null);
  const value = { data: Float64Array.of(1, 2), data_units: [{ display_units: "N", encoded_units: "" }, { display_units: "N*m", encoded_units: "" }] };
  assert.deepEqual(unitsOf(value, { name: "data", units: { field: "data_units", enumValues: null } }), ["N", "N*m"]);
  const codes = { joint_position: Float64Array.of(1), joint_position_units: Uint8Array.of(2) };
  assert.deepEqual(unitsOf(codes, { name: "joint_position", units: { field: "joint_position_units", enumValues: [{ name: "radian", value: 2 }] } }), ["radian"]);
  assert.equal(unitsOf({ data: [1], data_units: [] }, { name: "data", units: { field: "data_units" } }), null);
});

test("DataType as the type text it stands for, with the device's enum numbers", (t) => {
  const defs = standardDefinitions();
  if (!defs) return t.skip(SKIP_REASON);
  const d = standardDescriber(new RobdefOutline(defs)).describe("DataType", "com.robotraconteur.datatype");
  assert.ok(d.renderer, d.mismatch);
  // DataTypeCode: double_c 1, uint8_c 4, string_c 11, structure_c 101; ArrayTypeCode: array_c 1,
  // multidimarray_c 2; ContainerTypeCode: list_c 1, map_string_c 3 (numbers of the standard definition)
  const dt = (o) => typedText({ name: "", type_string: "", array_var_len: false, array_len: new Uint32Array(0),
    array_type_code: 0, container_type_code: 0, ...o }, d);
  assert.equal(dt({ type_code: 1 }), "double");
  assert.equal(dt({ type_code: 1, name: "focus" }), "double focus");
  assert.equal(dt({ type_code: 4, array_type_code: 1, array_var_len: true }), "uint8[]");
  assert.equal(dt({ type_code: 4, array_type_code: 1, array_len: Uint32Array.of(3) }), "uint8[3]");
  assert.equal(dt({ type_code: 4, array_type_code: 1, array_var_len: true, array_len: Uint32Array.of(8) }), "uint8[8-]");
  assert.equal(dt({ type_code: 1, array_type_code: 2, array_len: Uint32Array.of(2, 3) }), "double[2,3]");
  assert.equal(dt({ type_code: 1, array_type_code: 2, array_var_len: true }), "double[*]");
  assert.equal(dt({ type_code: 11, container_type_code: 1 }), "string{list}");
  assert.equal(dt({ type_code: 101, type_string: "com.robotraconteur.geometry.Pose", container_type_code: 3 }),
    "com.robotraconteur.geometry.Pose{string}");
});
