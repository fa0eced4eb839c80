// The tool panel's pure parts (src/tool/tool_state.js): hold-to-run (halt() after every hold that
// moved, never before the motion call's answer, none after a refused call), flag tones, millimetres,
// the open fraction, the command range, sensor rows and tool_info rows with units.
import { test } from "node:test";
import assert from "node:assert/strict";
import { ToolHold, toolFlagTone, toolFlagChips, mmText, openFraction, commandRange, sensorRows, toolInfoRows } from "../src/tool/tool_state.js";

const FLAGS = [["error", 1], ["enabled", 0x10], ["ready", 0x20], ["opened", 0x40], ["closed", 0x80], ["between", 0x100],
  ["actuating", 0x200], ["gripping", 0x2000], ["missed", 0x4000]].map(([name, value]) => ({ name, value }));
const CAPS = [["open_close_command", 1], ["continuous_command", 2], ["homing_command", 4]].map(([name, value]) => ({ name, value }));
const TYPES = [["unknown", 0], ["electric_gripper", 4], ["vacuum_gripper", 5]].map(([name, value]) => ({ name, value }));
const SENSOR = [["force", 40], ["pressure", 7]].map(([name, value]) => ({ name, value }));

function deferred() {
  let resolve, reject;
  const promise = new Promise((a, b) => { resolve = a; reject = b; });
  return { promise, resolve, reject };
}
const settle = () => new Promise((r) => setImmediate(r));

test("hold: halt() only after the motion call answered, once per hold", async () => {
  const order = [];
  const call = deferred();
  const stops = [];
  const hold = new ToolHold({ halt: async () => { order.push("halt"); }, onStop: (r) => stops.push(r) });
  hold.start("close", () => { order.push("close"); return call.promise; });
  assert.equal(hold.active, true);
  const stopped = hold.stop("release");
  assert.equal(hold.active, false);
  assert.deepEqual(stops, ["release"]);
  await settle();
  assert.deepEqual(order, ["close"], "halt() overtook the unanswered close()");
  call.resolve();
  await stopped;
  assert.deepEqual(order, ["close", "halt"]);
  await hold.stop("again");  // no hold: nothing
  assert.equal(hold.halts, 1);
  assert.deepEqual(stops, ["release"]);
});

test("hold: a refused call ends the hold without halt(); the error is reported", async () => {
  const errors = [], stops = [];
  let halts = 0;
  const hold = new ToolHold({ halt: async () => { halts++; }, onError: (e, what) => errors.push(`${what}: ${e.message}`), onStop: (r) => stops.push(r) });
  await hold.start("open", async () => { throw new Error("Tool is not enabled"); });
  assert.equal(hold.active, false);
  assert.deepEqual(stops, ["refused"]);
  assert.deepEqual(errors, ["open: Tool is not enabled"]);
  await hold.stop("release");
  assert.equal(halts, 0);
  // a call that throws at once (the page's own check) is the same
  await hold.start("setf_command", () => { throw new Error("enter a position"); });
  assert.equal(hold.active, false);
  assert.equal(halts, 0);
});

test("hold: a new hold ends the one before (halted); a failing halt() is reported", async () => {
  const order = [], errors = [];
  const hold = new ToolHold({ halt: async () => { order.push("halt"); throw new Error("gone"); }, onError: (e, what) => errors.push(what) });
  await hold.start("open", async () => { order.push("open"); });
  await hold.start("close", async () => { order.push("close"); });
  await hold.stop("release");
  await settle();
  assert.deepEqual(order, ["open", "halt", "close", "halt"]);
  assert.deepEqual(errors, ["halt", "halt"]);
});

test("flags, millimetres, open fraction, command range", () => {
  assert.equal(toolFlagTone("gripping"), "good");
  assert.equal(toolFlagTone("missed"), "bad");
  assert.equal(toolFlagTone("actuating"), "warn");
  assert.equal(toolFlagTone("between"), "info");
  assert.deepEqual(toolFlagChips(FLAGS, 0x10 | 0x20 | 0x2000), [{ name: "enabled", tone: "good" }, { name: "ready", tone: "good" }, { name: "gripping", tone: "good" }]);
  assert.deepEqual(toolFlagChips(FLAGS, 0x80000).map((c) => c.name), ["0x80000"]);
  assert.equal(mmText(0.0425), "42.5 mm");
  assert.equal(mmText(0.06173456), "61.73 mm");
  assert.equal(mmText(undefined), "");
  const info = { close_position: 0, open_position: 0.085, command_min: 0, command_max: 0.085 };
  assert.equal(openFraction(0.0425, info), 0.5);
  assert.equal(openFraction(0.2, info), 1);
  assert.equal(openFraction(0.02, { close_position: 0.08, open_position: 0 }), 0.75);  // reversed stroke
  assert.equal(openFraction(0.02, { close_position: 0, open_position: 0 }), null);
  assert.deepEqual(commandRange(info), [0, 0.085]);
  assert.equal(commandRange({ command_min: 1, command_max: 1 }), null);
  assert.equal(commandRange({}), null);
});

test("sensor rows and tool_info rows carry the units the tool gives", () => {
  const info = {
    tool_type: 4, tool_capabilities: 3, close_position: 0, open_position: 0.085, command_min: 0, command_max: 0.085,
    actuation_time: 0.85, sensor_type: [40, 7], sensor_min: Float64Array.from([0, -1]), sensor_max: Float64Array.from([235, 0]),
    sensor_units: [{ display_units: "N" }, { display_units: "bar" }],
  };
  assert.deepEqual(sensorRows({ sensor: Float64Array.from([12.3456, -0.5]) }, info, SENSOR),
    [{ label: "force", text: "12.346 N" }, { label: "pressure", text: "-0.5 bar" }]);
  assert.deepEqual(sensorRows({ sensor: [1, 2] }, {}, SENSOR), [{ label: "sensor 0", text: "1" }, { label: "sensor 1", text: "2" }]);
  assert.deepEqual(toolInfoRows(info, { type: TYPES, cap: CAPS, sensor: SENSOR }).map((r) => `${r.key}=${r.text}`), [
    "tool_type=electric_gripper",
    "tool_capabilities=open_close_command | continuous_command",
    "stroke=0 mm / 85 mm",
    "command_range=0 mm to 85 mm",
    "actuation_time=0.85 s",
    "sensors=force 0 to 235 N, pressure -1 to 0 bar",
  ]);
  assert.deepEqual(toolInfoRows({ tool_type: 99, tool_capabilities: 0 }, { type: TYPES, cap: CAPS, sensor: SENSOR }).map((r) => r.text), ["99", "none"]);
  assert.deepEqual(toolInfoRows(null, {}), []);
});
