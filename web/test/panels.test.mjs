// Panels chosen from the type (src/panels/): the registry by implemented object type and by members,
// the device card's rows from a DeviceInfo, which standard objects get a device card and a camera
// panel (against the standard definitions read at test time, and an older DeviceInfo layout that
// gets none); what a plot takes from a typed value (src/views/plot_sample.js); the view context.
import { test } from "node:test";
import assert from "node:assert/strict";
import { PanelRegistry, objectTypes } from "../src/panels/registry.js";
import { standardPanels } from "../src/panels/standard.js";
import { deviceInfoMember } from "../src/panels/device_card.js";
import { structRows } from "../src/panels/camera_panel.js";
import { deviceInfoRows } from "../src/std/device_info.js";
import { RobdefOutline } from "../src/std/robdef_outline.js";
import { viewContext, describeMember } from "../src/views/context.js";
import { plotSample } from "../src/views/plot_sample.js";
import { standardDefinitions, SKIP_REASON } from "./std_fixtures.mjs";

const defs = standardDefinitions();
const uuid = (...bytes) => ({ uuid_bytes: Uint8Array.from({ length: 16 }, (_, i) => bytes[i] ?? 0) });

/** A stand-in for the client package's proxy of an object of type `qualified`: $members from its definition. */
function proxyOf(outline, qualified) {
  const def = outline.types.get(qualified);
  assert.ok(def, qualified);
  const implementsList = [];
  const members = [];
  for (const m of def.members) {
    const words = m.text.replace(/\[[^\]]*\]\s*$/, "").trim().split(/\s+/);
    if (m.kind === "implements") { implementsList.push(outline.typeOf(words[1], def.service)?.qualified ?? words[1]); continue; }
    const fn = /^(\S+)\s+(\w+)\s*\(/.exec(words.slice(1).join(" "));
    members.push(fn ? { kind: m.kind, type: fn[1], name: fn[2], params: [] }
      : { kind: m.kind, type: words[1], name: words[2], readonly: /readonly/.test(m.text) });
  }
  return { $type: qualified, $implements: implementsList, $members: members };
}

test("the registry: by implemented type, by members, in order; a throwing applies() counts as no", () => {
  const made = [];
  const reg = new PanelRegistry().register(
    { name: "b", types: ["x.B"], order: 50, create: () => made.push("b") },
    { name: "a", types: ["x.A"], create: () => made.push("a") },
    { name: "m", applies: (obj) => obj.$members.some((m) => m.name === "special"), order: 5, create: () => {} },
    { name: "bad", applies: () => { throw new Error("no"); }, create: () => {} });
  const obj = { $type: "x.C", $implements: ["x.A", "x.B"], $members: [{ name: "special" }] };
  assert.deepEqual([...objectTypes(obj)], ["x.C", "x.A", "x.B"]);
  assert.deepEqual(reg.panelsFor(obj).map((p) => p.name), ["m", "b", "a"]);
  assert.deepEqual(reg.panelsFor({ $type: "x.A", $members: [] }).map((p) => p.name), ["a"]);
  assert.deepEqual(reg.panelsFor({ $type: "y.Z" }).map((p) => p.name), []);
  // registering again under the same name replaces
  reg.register({ name: "a", types: ["x.Q"], create: () => {} });
  assert.deepEqual(reg.panelsFor(obj).map((p) => p.name), ["m", "b"]);
  assert.throws(() => reg.register({ name: "z", create: () => {} }), /types or applies/);
  assert.throws(() => reg.register({ types: ["x.A"], create: () => {} }), /name/);
});

test("device card rows from a DeviceInfo value", () => {
  const info = {
    device: { name: "arm", uuid: uuid(0xab, 0xcd) },
    parent_device: { name: "", uuid: uuid() },
    manufacturer: { name: "Acme", uuid: uuid(1) },
    model: { name: "M1", uuid: uuid() },
    serial_number: "S-1",
    user_description: "",
    device_classes: [{ class_identifier: { name: "robot", uuid: uuid() }, subclasses: ["serial", "cobot"] }],
    implemented_types: ["com.robotraconteur.robotics.robot.Robot"],
  };
  const rows = deviceInfoRows(info, ["com.robotraconteur.robotics.robot.Robot", "com.robotraconteur.device.Device"]);
  assert.deepEqual(rows.map((r) => [r.key, r.text]), [
    ["name", "arm"],
    ["uuid", "abcd0000-0000-0000-0000-000000000000"],
    ["manufacturer", "Acme (01000000-0000-0000-0000-000000000000)"],
    ["model", "M1"],
    ["serial", "S-1"],
    ["classes", "robot (serial, cobot)"],
    ["types", "com.robotraconteur.robotics.robot.Robot, com.robotraconteur.device.Device"],
  ]);
  assert.deepEqual(deviceInfoRows(null), []);
  assert.deepEqual(deviceInfoRows({ device: null, serial_number: 7 }).map((r) => r.key), ["name"]);
});

test("standard objects get their panels: a camera its card and camera panel, a robot its card and robot panel", (t) => {
  if (!defs) { t.skip(SKIP_REASON); return; }
  const outline = new RobdefOutline(defs);
  const view = viewContext(outline);
  const panels = standardPanels();
  const camera = proxyOf(outline, "com.robotraconteur.imaging.Camera");
  assert.ok(camera.$implements.includes("com.robotraconteur.device.Device"));
  assert.deepEqual(panels.panelsFor(camera, view).map((p) => p.name), ["device-card", "camera"]);
  const robot = proxyOf(outline, "com.robotraconteur.robotics.robot.Robot");
  assert.deepEqual(panels.panelsFor(robot, view).map((p) => p.name), ["device-card", "robot"]);
  assert.equal(deviceInfoMember(robot, view).name, "device_info");
  // any object with a standard device_info gets the card, whatever it implements
  const other = { $type: "example.Thing", $implements: [], $members: [{ kind: "property", name: "device_info", type: "com.robotraconteur.device.DeviceInfo" }] };
  assert.deepEqual(panels.panelsFor(other, view).map((p) => p.name), ["device-card"]);
  // a device_info of another type, or none: no card
  assert.deepEqual(panels.panelsFor({ $type: "example.Thing", $members: [{ kind: "property", name: "device_info", type: "string" }] }, view), []);
  // an older DeviceInfo layout (serial_number under another name): no card, the generic view shows it
  const old = { ...defs };
  old["com.robotraconteur.device"] = defs["com.robotraconteur.device"].replace("field string serial_number", "field string serial");
  const oldView = viewContext(new RobdefOutline(old));
  assert.match(describeMember(oldView, camera, { name: "device_info", type: "DeviceInfo" }).type.mismatch, /serial_number/);
  assert.deepEqual(panels.panelsFor(camera, oldView).map((p) => p.name), ["camera"]);
});

test("every object type of the standard definitions opens as a panel of its own (issue 54), the abstract ones as parts", (t) => {
  if (!defs) { t.skip(SKIP_REASON); return; }
  const outline = new RobdefOutline(defs);
  const view = viewContext(outline);
  const panels = standardPanels();
  // Device, DeviceClock and IsochDevice are implemented by the others (their card, clock and frame
  // rate show there); every other object type must get more than the generic view.
  const parts = new Set(["com.robotraconteur.device.Device", "com.robotraconteur.device.clock.DeviceClock", "com.robotraconteur.device.isoch.IsochDevice"]);
  const objects = [...outline.types.values()].filter((d) => d.kind === "object").map((d) => d.qualified);
  assert.ok(objects.length >= 40, `only ${objects.length} object types read`);
  const without = objects.filter((q) => !parts.has(q) && !panels.panelsFor(proxyOf(outline, q), view).some((p) => p.name !== "device-card"));
  assert.deepEqual(without, [], `standard object types shown only as the generic view: ${without.join(", ")}`);
});

test("members described once: flags of a camera's capabilities, generators by what they yield", (t) => {
  if (!defs) { t.skip(SKIP_REASON); return; }
  const outline = new RobdefOutline(defs);
  const view = viewContext(outline);
  assert.equal(view.encodings.find((e) => e.name === "bgr888").value, 0x1002);
  assert.equal(view.clockEnum.find((e) => e.name === "sim_clock_scaled").value, 10);
  const camera = proxyOf(outline, "com.robotraconteur.imaging.Camera");
  const caps = describeMember(view, camera, camera.$members.find((m) => m.name === "capabilities"));
  assert.deepEqual(caps.flags.map((f) => f.name).slice(0, 3), ["unknown", "still", "stream"]);
  const part = describeMember(view, { $type: "com.robotraconteur.imaging.ImagePartCamera" }, { name: "capture_frame", type: "ImagePart{generator}" });
  assert.equal(part.type.qualified, "com.robotraconteur.image.ImagePart");
  assert.equal(describeMember(null, camera, { name: "x", type: "double" }), null);
  // rows of a structure for the camera panel: each field readable, extended left out
  const calibration = view.types.describe("CameraCalibration", "com.robotraconteur.imaging.camerainfo");
  const rows = structRows({ image_size: { width: 320, height: 240 }, K: { dims: [3, 3], array: new Float64Array(9) }, parent_device: null, extended: {} },
    calibration, view.text);
  assert.deepEqual(rows.map((r) => r.label), ["image_size", "K"]);
  assert.equal(rows[0].text, "{width: 320, height: 240}");
});

test("plots: a robot's sensor data without UUID bytes or clocks, on its own timestamp", (t) => {
  if (!defs) { t.skip(SKIP_REASON); return; }
  const view = viewContext(new RobdefOutline(defs));
  const d = view.types.describe("RobotStateSensorData", "com.robotraconteur.robotics.robot");
  const ts = { clock_info: { clock_type: 1, clock_uuid: uuid(9, 9, 9) }, seconds: 1700000000n, nanoseconds: 250000000 };
  const value = {
    data_header: { ts, seqno: 7n, source_info: { source: { name: "arm", uuid: uuid(1, 2, 3) }, source_world_pose: null, source_data: null, extended: null } },
    robot_state: { ts: { microseconds: 1700000000250000n }, seqno: 7n, robot_state_flags: 0x60000n, joint_position: new Float64Array([0.1, 0.2]),
      joint_position_units: new Uint8Array([2, 2]), command_mode: 1 },
  };
  const { pairs, t: time } = plotSample(value, d);
  const names = pairs.map(([n]) => n);
  assert.ok(names.includes("robot_state.joint_position[1]"), names.join(" "));
  assert.ok(!names.some((n) => /uuid|source_info|\.ts|microseconds|joint_position_units/.test(n)), names.join(" "));
  assert.ok(pairs.find(([n]) => n === "robot_state.robot_state_flags")[2], "flags start hidden");
  assert.equal(time, 1700000000.25);
  // a value the page could not describe: the generic numbers, no time
  assert.deepEqual(plotSample({ a: 1, b: [2, 3] }, null).pairs, [["a", 1], ["b[0]", 2], ["b[1]", 3]]);
  assert.deepEqual(plotSample({ a: 1 }, { kind: "unknown" }), { pairs: [["a", 1]], t: null });
});
