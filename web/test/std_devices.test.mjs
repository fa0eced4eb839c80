// The pure parts of the joystick, signal and other standard device panels (issue 54, stdpanels-c):
// values as a person reads them, from hand-made values with the enums of the standard definitions.
import { test } from "node:test";
import assert from "node:assert/strict";
import { axisFraction, axisText, pressedButtons, hatText, gamepadRows, joystickInfoRows } from "../src/hid/joystick.js";

const HAT = [["hat_centered", 0], ["hat_up", 1], ["hat_right", 2], ["hat_down", 4], ["hat_left", 8], ["hat_rightup", 3]].map(([name, value]) => ({ name, value }));
const GP = [["button_A", 1], ["button_B", 2], ["button_X", 4], ["button_Y", 8], ["button_dpad_right", 0x4000]].map(([name, value]) => ({ name, value }));
const CAPS = [["none", 0], ["rumble", 1], ["force_feedback", 2], ["standard_gamepad", 4]].map(([name, value]) => ({ name, value }));

test("joystick: int16 axes as a share of their travel both ways", () => {
  assert.equal(axisFraction(32767), 1);
  assert.equal(axisFraction(-32768), -1);
  assert.equal(axisFraction(0), 0);
  assert.equal(axisFraction("x"), 0);
  assert.equal(axisText(16384), "16384 (50%)");
  assert.equal(axisText(-32768), "-32768 (-100%)");
  assert.equal(axisText(-100), "-100 (0%)");
  assert.deepEqual(pressedButtons(Uint8Array.from([1, 0, 0, 255, 0])), [0, 3]);
  assert.deepEqual(pressedButtons(undefined), []);
  assert.equal(hatText(HAT, 2), "hat_right");
  assert.equal(hatText(HAT, 3), "hat_rightup");
  assert.equal(hatText(HAT, 99), "99");
});

test("joystick: gamepad state rows and joystick_info rows", () => {
  const rows = gamepadRows({ left_x: 16384, left_y: -32768, right_x: 0, right_y: 32767, trigger_left: 0, trigger_right: 32767, buttons: 1 | 8 | 0x4000 }, GP);
  assert.deepEqual(rows.map((r) => r.text), ["(50%, -100%)", "(0%, 100%)", "left 0%, right 100%", "A | Y | dpad_right"]);
  assert.equal(gamepadRows({ left_x: -1, left_y: 0, right_x: 0, right_y: 0, buttons: 0 }, GP)[0].text, "(0%, 0%)");
  assert.equal(gamepadRows({ buttons: 0 }, GP)[3].text, "none");
  const info = joystickInfoRows({ id: 0, axes_count: 4, button_count: 12, hat_count: 1, joystick_capabilities: 5,
    joystick_device_vendor: 0x045e, joystick_device_product: 0x028e, joystick_device_version: 0x110 }, CAPS);
  assert.deepEqual(Object.fromEntries(info.map((r) => [r.key, r.text])),
    { id: "0", counts: "4 axes, 12 buttons, 1 hats", capabilities: "rumble | standard_gamepad", usb: "045e:028e v0110" });
  assert.deepEqual(joystickInfoRows(null, CAPS), []);
});

import { signalNumbers, signalKind, signalText, signalCommand } from "../src/signal/signal_state.js";

const SIGTYPE = ["unknown", "digital", "analog", "digital_port"].map((name, value) => ({ name, value }));
const ACCESS = ["undefined", "internal", "restricted", "readonly", "all"].map((name, value) => ({ name, value }));
const ENUMS = { type: SIGTYPE, access: ACCESS };
const info = (over) => ({ signal_identifier: { name: "s" }, signal_type: 2, access_level: 4, units: [{ display_units: "bar" }], min_value: null, max_value: null, ...over });

test("signals: varvalues and vectors as numbers; on/off for digital, units otherwise", () => {
  assert.deepEqual(signalNumbers({ type: "bool[]", value: [true] }), [1]);
  assert.deepEqual(signalNumbers({ type: "double[]", value: Float64Array.of(4.25) }), [4.25]);
  assert.deepEqual(signalNumbers(Int32Array.of(1, 2)), [1, 2]);
  assert.deepEqual(signalNumbers({ type: "int64[]", value: BigInt64Array.of(7n) }), [7]);
  assert.equal(signalNumbers({ type: "string", value: "x" }), null);
  assert.equal(signalNumbers(null), null);
  const analog = signalKind(info(), ENUMS);
  assert.deepEqual([analog.type, analog.access, analog.writable, analog.units], ["analog", "all", true, ["bar"]]);
  assert.equal(signalText({ type: "double[]", value: Float64Array.of(6.12345) }, analog), "6.1235 bar");
  const digital = signalKind(info({ signal_type: 1, access_level: 3, units: [] }), ENUMS);
  assert.equal(digital.writable, false, "readonly");
  assert.equal(signalText({ type: "bool[]", value: [false] }, digital), "off");
  assert.equal(signalText(Float64Array.of(1), digital), "on");
  assert.equal(signalKind(info({ access_level: 2 }), ENUMS).writable, false, "restricted");
  const two = signalKind(info({ units: [{ display_units: "m" }, { display_units: "s" }] }), ENUMS);
  assert.equal(signalText(Float64Array.of(1, 2), two), "1 m, 2 s");
  assert.equal(signalText({ type: "string", value: "ok" }, analog), '"ok"');
});

test("signals: commands as double[], checked against min and max before sending", () => {
  const k = signalKind(info({ min_value: { type: "double[]", value: Float64Array.of(0) }, max_value: { type: "double[]", value: Float64Array.of(0.5) } }), ENUMS);
  assert.deepEqual([k.min, k.max], [0, 0.5]);
  assert.deepEqual(Array.from(signalCommand(k, "0.25")), [0.25]);
  assert.deepEqual(Array.from(signalCommand(k, true)), [1]);
  assert.deepEqual(Array.from(signalCommand(k, false)), [0]);
  assert.throws(() => signalCommand(k, "0.8"), /0\.8 is above its maximum 0\.5/);
  assert.throws(() => signalCommand(k, "-1"), /below its minimum 0/);
  assert.throws(() => signalCommand(k, ""), /enter a number/);
  assert.throws(() => signalCommand(k, "abc"), /enter a number/);
});

import { clockOffset, offsetText, clockText, zoneText } from "../src/clock/clock.js";
import { messageRow, passes, mergeRows, newestWindow } from "../src/eventlog/event_log.js";
import { assembleParts, sizeText } from "../src/resource/resource.js";

test("clock: offset from the browser's clock, times and zones as text", () => {
  const t = [{ clock_info: { clock_type: 2 }, seconds: 1790000030n, nanoseconds: 500000000 }];
  assert.equal(clockOffset(t, 1790000000000), 30.5);
  assert.equal(clockOffset({ nothing: 1 }, 0), null);
  assert.equal(offsetText(30.5), "+30.500 s");
  assert.equal(offsetText(-0.012), "-12 ms");
  assert.equal(offsetText(null), "");
  assert.equal(clockText(t), "2026-09-21T14:13:50.5Z");
  assert.equal(clockText({ seconds: 1790000030n, nanoseconds: 0, utc_offset_seconds: 7200, timezone_name: "Europe/Berlin" }), "2026-09-21T16:13:50+02:00 Europe/Berlin");
  assert.equal(zoneText({ timezone_utc_offset_seconds: -16200, timezone_name: "" }), "-04:30");
});

test("event log: rows, filters by words and level, merge newest first and bounded, the newest window", () => {
  const LEVELS = [["undefined", 0], ["trace", 1], ["debug", 2], ["info", 3], ["warning", 4], ["error", 5]].map(([name, value]) => ({ name, value }));
  const msg = (n, level, title) => ({ header: { level, message_number: BigInt(n), source_device: { name: "plc" }, source_component: "line", source_object: "",
    timestamp: [{ seconds: 1790000000n, nanoseconds: 0 }] }, title, message: "m" });
  const r = messageRow(msg(7, 5, "conveyor jam"), LEVELS);
  assert.deepEqual([r.number, r.level, r.source, r.time], [7n, "error", "plc / line", "2026-09-21T14:13:20Z"]);
  assert.equal(passes(r, "Conveyor JAM", 0), true);
  assert.equal(passes(r, "jam heartbeat", 0), false);
  assert.equal(passes(r, "", 5), true);
  assert.equal(passes(messageRow(msg(8, 4, "x"), LEVELS), "", 5), false);
  const rows = mergeRows([messageRow(msg(1, 3, "a"), LEVELS)], [2, 3, 1].map((n) => messageRow(msg(n, 3, `b${n}`), LEVELS)), 2);
  assert.deepEqual(rows.map((x) => [x.number, x.title]), [[3n, "b3"], [2n, "b2"]]);
  assert.deepEqual(newestWindow({ min_message_number: 1n, max_message_number: 50n }, 20), { start: 31n, count: 20n });
  assert.deepEqual(newestWindow({ min_message_number: 5n, max_message_number: 9n }, 20), { start: 5n, count: 5n });
  assert.equal(newestWindow({ min_message_number: 5n, max_message_number: 4n }), null);
});

test("resources: parts put together, bounded; sizes as text", () => {
  const info = { total_size: 5n };
  const part = (off, bytes) => ({ info, data_offset: BigInt(off), data: Uint8Array.from(bytes) });
  assert.deepEqual(Array.from(assembleParts([part(3, [4, 5]), part(0, [1, 2, 3])])), [1, 2, 3, 4, 5]);
  assert.throws(() => assembleParts([part(4, [1, 2])]), /outside the resource's 5/);
  assert.throws(() => assembleParts([part(0, [1, 2])]), /3 of the resource's 5 bytes did not come/);
  assert.throws(() => assembleParts([{ info: { total_size: 100 }, data_offset: 0, data: new Uint8Array(1) }], 10), /more than the 10/);
  assert.equal(assembleParts([]).length, 0);
  assert.equal(sizeText(3000), "2.9 KiB");
  assert.equal(sizeText(12), "12 B");
});

import { trajectorySeries, trajectoryText, drawTrajectory } from "../src/std/trajectory.js";
import { formatPid, formatParameterInfo, varText } from "../src/std/param.js";

test("JointTrajectory: series per joint over time (radians in degrees), text, drawn lines", () => {
  const UNITS = [["implicit", 0], ["meter", 1], ["radian", 2], ["degree", 3]].map(([name, value]) => ({ name, value }));
  const traj = { joint_names: ["shoulder", "rail"], joint_units: [2, 1], waypoints: [0, 1, 2].map((k) => ({ joint_position: Float64Array.of(k * Math.PI / 4, 0.1 * k), time_from_start: 0.5 * k })) };
  const s = trajectorySeries(traj, UNITS);
  assert.deepEqual(s.names, ["shoulder", "rail"]);
  assert.deepEqual(Array.from(s.times), [0, 0.5, 1]);
  assert.deepEqual(Array.from(s.series[0], (v) => Math.round(v * 1e9) / 1e9), [0, 45, 90]);
  assert.deepEqual(Array.from(s.series[1]), [0, 0.1, 0.2]);
  assert.deepEqual(s.unitText, ["°", "m"]);
  assert.equal(trajectoryText(traj), "2 joints, 3 waypoints over 1 s (shoulder, rail)");
  assert.equal(trajectorySeries({ waypoints: [] }), null);
  assert.equal(trajectoryText({ joint_names: [] }), "joint trajectory without waypoints");
  // drawing: a stand-in 2D context records the lines
  const lines = [];
  let current = null;
  const g = { fillRect() {}, strokeRect() {}, fillText() {}, measureText: (t) => ({ width: t.length * 6 }), beginPath() { current = []; },
    moveTo(x, y) { current.push([x, y]); }, lineTo(x, y) { current.push([x, y]); }, stroke() { if (current) lines.push(current); current = null; } };
  const r = drawTrajectory(g, s, 480, 260);
  assert.deepEqual([r.min, r.max, r.t0, r.t1], [0, 90, 0, 1]);
  assert.equal(lines.length, 2);
  assert.equal(lines[0].length, 3);
  assert.ok(lines[0][2][1] < lines[0][0][1], "the shoulder's line rises");
});

test("PIDParam and ParameterInfo as one line", () => {
  assert.equal(formatPid({ p: 1.2, i: 0.05, d: 0.01, imax: 5, imin: -5, cmd_max: 10, cmd_min: -10 }), "P 1.2, I 0.05, D 0.01; integral -5 … 5; command -10 … 10");
  assert.equal(formatPid(null), null);
  assert.equal(varText({ type: "double[]", value: Float64Array.of(0.1, 2) }), "0.1, 2");
  assert.equal(varText({ type: "string", value: "auto" }), '"auto"');
  assert.equal(varText(null), "");
  const info = { parameter_identifier: { name: "exposure" }, data_type: { name: "", type_code: 1, type_string: "", array_type_code: 0, array_len: [], container_type_code: 0 },
    data_units: [{ display_units: "ms" }], description: "exposure time", default_value: { type: "double[]", value: Float64Array.of(10) },
    min_value: { type: "double[]", value: Float64Array.of(0.1) }, max_value: { type: "double[]", value: Float64Array.of(100) }, enum_values: {} };
  const d = { fields: [{ name: "data_type", type: { fields: [{ name: "type_code", type: { enumValues: [{ name: "double_c", value: 1 }] } }] } }] };
  assert.equal(formatParameterInfo(info, { descriptor: d }), "exposure (double, ms): exposure time, default 10, 0.1 … 100");
  assert.equal(formatParameterInfo({ parameter_identifier: { name: "mode" }, enum_values: { fast: {}, slow: {} } }), "mode: one of fast, slow");
});

import { sceneTree, treeLines, MAX_LINKS } from "../src/planning/scene_tree.js";

test("planning scene: the tree of links from the root, joints between, models marked; loops and size bounded", () => {
  const j = (name, parent, child, type = 1) => ({ joint_info: { joint_identifier: { name }, joint_type: type }, parent_link_name: parent, child_link_name: child });
  const l = (name) => ({ link_identifier: { name } });
  const scene = { links: [l("world"), l("table")], joints: [j("mount", "world", "table", 6)],
    models: [{ model_identifier: { name: "robot" }, links: [l("base"), l("link_1")], joints: [j("base_mount", "table", "base", 6), j("joint_1", "base", "link_1")] }] };
  const t = sceneTree(scene, "world");
  assert.deepEqual([t.placed, t.total], [4, 4]);
  assert.deepEqual(treeLines(t.tree, (v) => ({ 1: "revolute", 6: "other" })[v]),
    ["world", "  mount (other) → table", "    base_mount (other) → base [robot]", "      joint_1 (revolute) → link_1 [robot]"]);
  // a loop (link_1 → world) leaves no root: nothing is placed twice, and the tree is empty rather than endless
  const loop = sceneTree({ links: [], joints: [j("a", "x", "y"), j("b", "y", "x")] });
  assert.equal(loop.placed, 0);
  // a chain longer than the bound is cut
  const long = { links: [], joints: Array.from({ length: MAX_LINKS + 10 }, (_, i) => j(`j${i}`, `l${i}`, `l${i + 1}`)) };
  assert.equal(sceneTree(long).placed, MAX_LINKS);
});
