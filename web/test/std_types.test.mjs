// Type recognition of the standard types (src/std/describe.js, registry.js, standard.js) against the
// real standard definitions read at test time, older or other layouts falling back to the generic
// view, flag and unit fields found by their names, and what plots take (plot_fields.js).
import { test } from "node:test";
import assert from "node:assert/strict";
import { RobdefOutline } from "../src/std/robdef_outline.js";
import { standardDescriber, standardRegistry } from "../src/std/standard.js";
import { TypeDescriber, fieldAt, qualifyType } from "../src/std/describe.js";
import { RendererRegistry } from "../src/std/registry.js";
import { typedText, memberText } from "../src/std/typed_text.js";
import { typedNumericFields, leaveOutOfPlot, plotRole, sensorTimestamp } from "../src/std/plot_fields.js";
import { formatValue } from "../src/std/value_text.js";
import { parseType } from "../src/std/rr_types.js";
import { standardDefinitions, SKIP_REASON } from "./std_fixtures.mjs";

const defs = standardDefinitions();
const skip = (t) => { t.skip(SKIP_REASON); return true; };
const R = "com.robotraconteur.robotics.robot";
const seq = Uint8Array.from({ length: 16 }, (_, i) => i);
const zeroUuid = { uuid_bytes: new Uint8Array(16) };

/** The standard texts with `service`'s text changed by `edit` (an older or other layout). */
function edited(service, edit) {
  const out = { ...defs };
  const before = out[service];
  out[service] = edit(before);
  assert.notEqual(out[service], before, `the edit of ${service} changed nothing`);
  return out;
}

test("every registered renderer's layout matches the standard definitions", (t) => {
  if (!defs) return skip(t);
  const types = standardDescriber(new RobdefOutline(defs));
  const registered = standardRegistry().types();
  assert.ok(registered.length >= 15, registered.join(" "));
  for (const q of registered) {
    const d = types.describe(q, "");
    assert.equal(d.mismatch, null, q);
    assert.equal(d.renderer?.type, q, q);
  }
});

test("names resolve through `using` and the service's own names, as robdef does", (t) => {
  if (!defs) return skip(t);
  const outline = new RobdefOutline(defs);
  const types = standardDescriber(outline);
  const image = types.describe("Image", "com.robotraconteur.imaging");
  assert.equal(image.qualified, "com.robotraconteur.image.Image");
  assert.equal(image.kind, "struct");
  assert.ok(image.renderer?.image);
  assert.equal(fieldAt(image, "image_info.encoding").type.kind, "enum");
  assert.equal(fieldAt(image, "image_info.data_header.ts").type.qualified, "com.robotraconteur.datetime.TimeSpec2");
  assert.equal(types.describe("Pose", R).qualified, "com.robotraconteur.geometry.Pose");
  assert.equal(types.describe("Pose", "com.robotraconteur.image").kind, "unknown");  // not `using`d there
  const list = types.describe("SIUnit{list}", "com.robotraconteur.sensor");
  assert.deepEqual([list.container, list.element.qualified, !!list.element.renderer], ["list", "com.robotraconteur.units.SIUnit", true]);
  const poses = types.describe("Pose[]", R);
  assert.deepEqual([poses.array, poses.element.qualified], ["vector", "com.robotraconteur.geometry.Pose"]);
  assert.equal(qualifyType(outline, "Vector3[]", R), "com.robotraconteur.geometry.Vector3[]");
  assert.equal(qualifyType(outline, "uint8[ 16 ]", R), "uint8[16]");
  // a `using ... as` alias in a device's own service
  const mine = { ...defs, "experimental.cam": "service experimental.cam\nimport com.robotraconteur.image\n"
    + "using com.robotraconteur.image.Image as Frame\nobject Cam\n  pipe Frame frames [readonly]\nend\n" };
  const aliased = standardDescriber(new RobdefOutline(mine)).describe("Frame", "experimental.cam");
  assert.equal(aliased.qualified, "com.robotraconteur.image.Image");
  assert.ok(aliased.renderer);
});

test("types only from the device's definitions: none sent, or a type of the same short name elsewhere, is generic", () => {
  const own = { "experimental.cam": "service experimental.cam\nstruct Image\n  field uint32 width\n  field uint32 height\n"
    + "  field uint8[] data\nend\nstruct UUID\n  field uint8[16] uuid_bytes\nend\n" };
  const types = standardDescriber(new RobdefOutline(own));
  const image = types.describe("Image", "experimental.cam");
  assert.deepEqual([image.qualified, image.renderer, image.mismatch], ["experimental.cam.Image", null, null]);
  assert.equal(types.describe("UUID", "experimental.cam").renderer, null);
  const absent = types.describe("com.robotraconteur.image.Image", "experimental.cam");
  assert.deepEqual([absent.kind, absent.renderer], ["unknown", undefined]);
});

test("older or other layouts of standard types fall back to the generic view with a reason", (t) => {
  if (!defs) return skip(t);
  const image = { image_info: { data_header: null, height: 1, width: 1, step: 3, encoding: 0x1000, extended: null }, data: Uint8Array.of(1, 2, 3) };

  // ImageInfo without `step`: Image and CompressedImage (which use it) are not recognised
  const noStep = standardDescriber(new RobdefOutline(edited("com.robotraconteur.image", (s) => s.replace(/\n\s*field uint32 step/, ""))));
  const img = noStep.describe("com.robotraconteur.image.Image", "");
  assert.equal(img.renderer, null);
  assert.match(img.mismatch, /Image\.image_info: com\.robotraconteur\.image\.ImageInfo has no field step/);
  assert.match(noStep.describe("com.robotraconteur.image.CompressedImage", "").mismatch, /no field step/);
  const text = typedText(image, img);
  assert.match(text, /^\{image_info: \{data_header: null, height: 1, width: 1, encoding: rgb888, extended: null\}, data: \[1, 2, 3\]\}$/);

  // encoding as a plain integer instead of the enum
  const intEncoding = standardDescriber(new RobdefOutline(edited("com.robotraconteur.image",
    (s) => s.replace("field ImageEncoding encoding", "field int32 encoding"))));
  assert.match(intEncoding.describe("com.robotraconteur.image.Image", "").mismatch, /encoding is int32, com\.robotraconteur\.image\.ImageEncoding expected/);

  // UUID bytes of another size: UUID, and Identifier (which holds one), are generic; DeviceInfo still shows
  const oddUuid = standardDescriber(new RobdefOutline(edited("com.robotraconteur.uuid", (s) => s.replace("uint8[16] uuid_bytes", "uint8[] uuid_bytes"))));
  assert.match(oddUuid.describe("com.robotraconteur.uuid.UUID", "").mismatch, /uuid_bytes is uint8\[\], uint8\[16\] expected/);
  const ident = oddUuid.describe("com.robotraconteur.identifier.Identifier", "");
  assert.equal(ident.renderer, null);
  assert.match(ident.mismatch, /Identifier\.uuid: .*uint8\[16\] expected/);
  const id = { name: "cam", uuid: { uuid_bytes: seq } };
  assert.equal(typedText(id, ident), `{name: "cam", uuid: {uuid_bytes: ${formatValue(seq)}}}`);

  // TimeSpec3 as double microseconds, Pose with its fields renamed: generic, and no throw on odd values
  const older = standardDescriber(new RobdefOutline({
    ...edited("com.robotraconteur.datetime", (s) => s.replace("field int64 microseconds", "field double microseconds")),
    "com.robotraconteur.geometry": defs["com.robotraconteur.geometry"].replace("field Point position", "field Point translation"),
  }));
  assert.equal(older.describe("com.robotraconteur.datetime.TimeSpec3", "").renderer, null);
  const pose = older.describe("com.robotraconteur.geometry.Pose", "");
  assert.match(pose.mismatch, /has no field position/);
  for (const v of [{}, { orientation: 5 }, "x", 7, [1, 2], new Uint8Array(3)]) assert.equal(typeof typedText(v, pose), "string");
  // a renderer that throws gives the generic text
  const registry = new RendererRegistry().register({ type: "com.robotraconteur.uuid.UUID", layout: {}, text: () => { throw new Error("boom"); } });
  const broken = new TypeDescriber(new RobdefOutline(defs), registry).describe("com.robotraconteur.uuid.UUID", "");
  assert.equal(typedText({ uuid_bytes: seq }, broken), formatValue({ uuid_bytes: seq }));
});

test("an older ImageEncoding numbering: the device's numbers decode", (t) => {
  if (!defs) return skip(t);
  const outline = new RobdefOutline(edited("com.robotraconteur.image", (s) => s.replace("rgb888 = 0x1000", "rgb888 = 0x10")));
  const d = standardDescriber(outline).describe("com.robotraconteur.image.Image", "");
  const v = { image_info: { height: 1, width: 1, step: 3, encoding: 0x10 }, data: Uint8Array.of(1, 2, 3) };
  const r = d.renderer.image(v, { outline });
  assert.deepEqual([r.ok, r.encoding, Array.from(r.data)], [true, "rgb888", [1, 2, 3, 255]]);
  assert.equal(typedText(v, d, { outline }), "1×1 rgb888, 3 bytes");
  // the values after it follow: 0x11 is rgba8888; the standard number 0x1000 is no encoding of this device
  const rgba = { image_info: { height: 1, width: 1, step: 4, encoding: 0x11 }, data: Uint8Array.of(1, 2, 3, 4) };
  assert.equal(d.renderer.image(rgba, { outline }).encoding, "rgba8888");
  assert.equal(d.renderer.image({ ...v, image_info: { ...v.image_info, encoding: 0x1000 } }, { outline }).error.code, "unknown_encoding");
});

const FLAG_FIELDS = {
  [`${R}.RobotState.robot_state_flags`]: `${R}.RobotStateFlags`,
  [`${R}.AdvancedRobotState.robot_state_flags`]: `${R}.RobotStateFlags`,
  [`${R}.RobotInfo.robot_capabilities`]: `${R}.RobotCapabilities`,
  "com.robotraconteur.imaging.CameraState.state_flags": "com.robotraconteur.imaging.CameraStateFlags",
  "com.robotraconteur.actuator.ActuatorState.actuator_state_flags": "com.robotraconteur.actuator.ActuatorStateFlags",
  "com.robotraconteur.gps.GpsStatus.motion_source_flags": "com.robotraconteur.gps.GpsMeasureSourceFlags",
  "com.robotraconteur.gps.GpsStatus.orientation_source_flags": "com.robotraconteur.gps.GpsMeasureSourceFlags",
  "com.robotraconteur.gps.GpsStatus.position_source_flags": "com.robotraconteur.gps.GpsMeasureSourceFlags",
  "com.robotraconteur.hid.joystick.JoystickInfo.joystick_capabilities": "com.robotraconteur.hid.joystick.JoystickCapabilities",
  "com.robotraconteur.robotics.tool.ToolInfo.tool_capabilities": "com.robotraconteur.robotics.tool.ToolCapabilities",
  "com.robotraconteur.robotics.tool.ToolState.tool_state_flags": "com.robotraconteur.robotics.tool.ToolStateFlags",
  "com.robotraconteur.sensor.SensorData.data_flags": "com.robotraconteur.sensor.SensorDataFlags",
  "com.robotraconteur.servo.ServoInfo.capabilities": "com.robotraconteur.servo.ServoCapabilities",
  "com.robotraconteur.servo.ServoState.servo_state_flags": "com.robotraconteur.servo.ServoStateFlags",
  "com.robotraconteur.signal.SignalDeviceState.signal_device_state_flags": "com.robotraconteur.signal.SignalDeviceStateFlags",
};

test("flag fields of the standard definitions find their enums; Camera's capabilities property too", (t) => {
  if (!defs) return skip(t);
  const outline = new RobdefOutline(defs);
  const types = standardDescriber(outline);
  const found = {};
  for (const s of outline.services) {
    for (const e of s.entries.filter((x) => x.fields.length)) {
      const d = types.describe(`${s.name}.${e.name}`, "");
      for (const f of d.fields) {
        if (f.flags) found[`${s.name}.${e.name}.${f.name}`] = f.flags;
        else if (/(flags|capabilities)$/.test(f.name)) {
          assert.ok(!/^u?int/.test(f.type.base), `${s.name}.${e.name}.${f.name}: an integer flag field without its enum`);
        }
      }
    }
  }
  assert.deepEqual(Object.keys(found).sort(), Object.keys(FLAG_FIELDS).sort());
  for (const [field, enumName] of Object.entries(FLAG_FIELDS)) assert.equal(found[field], outline.types.get(enumName).values, field);
  for (const camera of ["Camera", "ImagePartCamera"]) {
    const m = types.describeMember(`com.robotraconteur.imaging.${camera}`, { name: "capabilities", type: "uint32" });
    assert.equal(m.flags, outline.types.get("com.robotraconteur.imaging.Capabilities").values);
    assert.equal(memberText(0x13, m), "still | stream | software_trigger");
  }
  assert.equal(types.describeMember("com.robotraconteur.imaging.Camera", { name: "trigger_mode", type: "TriggerMode" }).flags, undefined);
});

function robotState(now) {
  const s = Math.SQRT1_2;
  return {
    ts: { microseconds: BigInt(now - 1500) * 1000n }, seqno: 42n, command_mode: 1, operational_mode: 3, controller_state: 2,
    robot_state_flags: 0x20000n | 0x40000n, joint_position: Float64Array.of(0.1, -0.2), joint_velocity: new Float64Array(2),
    joint_effort: new Float64Array(2), joint_position_command: new Float64Array(0), joint_velocity_command: new Float64Array(0),
    kin_chain_tcp: [{ orientation: { w: s, x: 0, y: 0, z: s }, position: { x: 0.5, y: 0, z: 0.25 } }],
    kin_chain_tcp_vel: [], trajectory_running: false,
  };
}

test("a robot state reads as text: time, enums by name, flags by name, poses", (t) => {
  if (!defs) return skip(t);
  const outline = new RobdefOutline(defs);
  const d = standardDescriber(outline).describe("RobotState", R);
  const now = Date.UTC(2024, 4, 1, 12);
  assert.equal(typedText(robotState(now), d, { now, outline }),
    "{ts: 2024-05-01T11:59:58.5Z (1.5 s ago), seqno: 42, command_mode: jog, operational_mode: auto, controller_state: motor_on, "
    + "robot_state_flags: enabled | ready, joint_position: [0.1, -0.2], joint_velocity: [0, 0], joint_effort: [0, 0], "
    + "joint_position_command: [], joint_velocity_command: [], kin_chain_tcp: [position (0.5, 0, 0.25) m, rpy (0, 0, 90)°], "
    + "kin_chain_tcp_vel: [], trajectory_running: false}");
  // units named by a sibling: SIUnit{list} and enum codes in uint8[]
  const sensor = standardDescriber(outline).describe("SensorData", "com.robotraconteur.sensor");
  const data = { data_header: null, data_flags: 0x403, data: Float64Array.of(1.5, 2), data_type: null,
    data_units: [{ display_units: "N", encoded_units: "kg*m*s^-2" }], parameters: null, extended: null };
  assert.match(typedText(data, sensor), /data_flags: enabled \| streaming \| ready, data: \[1\.5, 2\] N,/);
  const adv = standardDescriber(outline).describe("AdvancedRobotState", R);
  const state = { ...robotState(now), joint_position_units: Uint8Array.of(2, 3), joint_effort_units: new Uint8Array(0) };
  assert.match(typedText(state, adv, { now }), /joint_position: \[0\.1, -0\.2\] \(radian, degree\)/);
  // the codes themselves by name too (uint8[] of JointPositionUnits values), an unknown code said so
  assert.match(typedText(state, adv, { now }), /joint_position_units: \[radian, degree\], joint_effort_units: \[\],/);
  const odd = { ...state, joint_position_units: Uint8Array.of(1, 99) };
  assert.match(typedText(odd, adv, { now }), /joint_position_units: \[meter, 99 \(not a value of the enum\)\]/);
  // RobotJointCommand's `units` names no enum of its own: plain numbers
  const cmd = standardDescriber(outline).describe("RobotJointCommand", R);
  assert.match(typedText({ seqno: 1, state_seqno: 2, command: Float64Array.of(0), units: Uint8Array.of(2) }, cmd), /units: \[2\]\}$/);
});

test("plots leave out identifiers, UUIDs, byte arrays and clock fields; flags and sequence numbers start hidden", (t) => {
  if (!defs) return skip(t);
  const outline = new RobdefOutline(defs);
  const types = standardDescriber(outline);
  const now = Date.now();
  const series = typedNumericFields(robotState(now), types.describe("RobotState", R));
  const names = series.map(([n]) => n);
  assert.ok(!names.some((n) => n.startsWith("ts")), names.join(" "));
  assert.deepEqual(series.filter(([, , hidden]) => hidden).map(([n]) => n), ["seqno", "robot_state_flags"]);
  assert.ok(names.includes("joint_position[1]") && names.includes("kin_chain_tcp[0].position.x") && names.includes("command_mode"));
  // the readout names what the numbers mean: enums by name, flag words by their set flags; plain numbers get no label
  const labels = Object.fromEntries(series.map(([n, x, , label]) => [n, [x, label]]));
  assert.deepEqual(labels.command_mode, [1, "jog"]);
  assert.deepEqual(labels.operational_mode, [3, "auto"]);
  assert.deepEqual(labels.controller_state, [2, "motor_on"]);
  assert.deepEqual(labels.robot_state_flags, [0x60000, "enabled | ready"]);
  assert.deepEqual(labels["joint_position[1]"], [-0.2, undefined]);
  const odd = typedNumericFields({ ...robotState(now), command_mode: 99 }, types.describe("RobotState", R));
  assert.equal(odd.find(([n]) => n === "command_mode")[3], "99 (not a value of the enum)");

  const header = { ts: { clock_info: { clock_type: 1, clock_uuid: { uuid_bytes: seq }, offset_microseconds: 0n }, seconds: BigInt(Math.floor(now / 1000)), nanoseconds: 5000 },
    seqno: 7n, source_info: { source: { name: "cam", uuid: { uuid_bytes: seq } }, source_world_pose: null, source_config_nonce: "", source_params: null, extended: null } };
  const frame = { image_info: { data_header: header, height: 2, width: 2, step: 6, encoding: 0x1000, extended: null }, data: new Uint8Array(12) };
  const image = types.describe("Image", "com.robotraconteur.imaging");
  assert.deepEqual(typedNumericFields(frame, image).map(([n, , h]) => `${n}${h ? " (hidden)" : ""}`),
    ["image_info.data_header.seqno (hidden)", "image_info.height", "image_info.width", "image_info.step", "image_info.encoding"]);
  const joystick = types.describe("JoystickInfo", "com.robotraconteur.hid.joystick");
  for (const [name, role] of [["device_info", "show"], ["joystick_uuid", "omit"], ["joystick_capabilities", "hidden"], ["axes_count", "show"]]) {
    assert.equal(plotRole(joystick.fields.find((f) => f.name === name)), role, name);
  }
  const bytes = { name: "Data", type: types.describe("uint8[]", "") };
  assert.equal(leaveOutOfPlot(bytes), true);
  assert.equal(leaveOutOfPlot({ name: "x", type: types.describe("double[]", "") }), false);
  const clockNow = types.describe("DeviceTime", "com.robotraconteur.device.clock");
  assert.deepEqual(clockNow.fields.map(leaveOutOfPlot), [true, true, false]);
});

test("a value's own timestamp for the time axis: the sensor header's, a state's ts; unset is none", (t) => {
  if (!defs) return skip(t);
  const types = standardDescriber(new RobdefOutline(defs));
  const image = types.describe("Image", "com.robotraconteur.imaging");
  const ts = (seconds, nanoseconds) => ({ clock_info: { clock_type: 1 }, seconds, nanoseconds });
  const frame = (header) => ({ image_info: { data_header: header, height: 1, width: 1, step: 1, encoding: 0x2000 }, data: new Uint8Array(1) });
  assert.deepEqual(sensorTimestamp(frame({ ts: ts(1714564800n, 500000000), seqno: 1n }), image),
    { seconds: 1714564800.5, path: "image_info.data_header.ts", type: "com.robotraconteur.datetime.TimeSpec2" });
  assert.equal(sensorTimestamp(frame({ ts: ts(0n, 0), seqno: 1n }), image), null);  // a driver that leaves it unset
  assert.equal(sensorTimestamp(frame(null), image), null);
  const state = types.describe("RobotStateSensorData", R);
  const v = { data_header: { ts: ts(100n, 0), seqno: 1n }, robot_state: { ts: { microseconds: 200000000n } } };
  assert.equal(sensorTimestamp(v, state).path, "data_header.ts");
  assert.equal(sensorTimestamp({ data_header: null, robot_state: v.robot_state }, state).path, "robot_state.ts");
  assert.equal(sensorTimestamp(robotState(Date.UTC(2024, 0, 1)), types.describe("RobotState", R)).seconds, Date.UTC(2024, 0, 1) / 1000 - 1.5);
});

test("descriptors of the whole standard set build (recursive types included) and never throw on values", (t) => {
  if (!defs) return skip(t);
  const outline = new RobdefOutline(defs);
  const types = standardDescriber(outline);
  let count = 0;
  for (const [q, def] of outline.types) {
    if (!["struct", "pod", "namedarray", "enum"].includes(def.kind)) continue;
    const d = types.describe(q, "");
    count++;
    for (const v of [null, {}, 5, "x", new Uint8Array(2), [{}], new Map([[1, {}]])]) assert.equal(typeof typedText(v, d), "string", q);
    for (const f of d.fields || []) assert.ok(f.type.kind !== "unknown" || parseType(f.type.text).base.includes("?"), `${q}.${f.name}`);
  }
  assert.ok(count > 150, String(count));
});
