// The robot panel's pure parts (src/robot/): the hold-to-jog timer with fake timers (one call at
// once, one per 50 ms, none while two are outstanding, none after the hold ends in any way, an error
// ends it), joint rows from a RobotInfo and a RobotState (units, degrees, limit warnings within 5 %
// of the range), the jog_joint velocity, Cartesian velocity, status chips, staleness, access.
import { test } from "node:test";
import assert from "node:assert/strict";
import { JogRepeater, JOG_PERIOD_MS, JOG_TIMEOUT_S, JOG_MAX_IN_FLIGHT } from "../src/robot/jog_repeater.js";
import { jointModel, jointRows, limitState, jogVelocity, positionText, toDisplay, fromDisplay, NEAR_LIMIT_FRACTION } from "../src/robot/joints.js";
import { flagChips, flagTone, modeText, isStale, capabilitySet, STALE_MS } from "../src/robot/status.js";
import { accessUrl, fetchAccess, allows, mayLock } from "../src/robot/access.js";
import { jogKey, jogKeysText } from "../src/robot/hold.js";
import { cartesianVelocity, isNotImplemented, CARTESIAN_LINEAR_MPS } from "../src/robot/cartesian.js";
import { locksText } from "../src/robot/lock_text.js";

/** Fake setInterval/clearInterval driven by advance(ms). */
function fakeTimers() {
  let now = 0, next = 1;
  const timers = new Map();
  return {
    setInterval(fn, ms) { const id = next++; timers.set(id, { fn, ms, at: now + ms }); return id; },
    clearInterval(id) { timers.delete(id); },
    get count() { return timers.size; },
    advance(ms) {
      const end = now + ms;
      for (;;) {
        const due = [...timers.entries()].filter(([, t]) => t.at <= end).sort((a, b) => a[1].at - b[1].at)[0];
        if (!due) break;
        now = due[1].at;
        due[1].at += due[1].ms;
        due[1].fn();
      }
      now = end;
    },
  };
}
const settle = () => new Promise((r) => setImmediate(r));

test("jog timer: a call at once and one per 50 ms while held, none after release", async () => {
  assert.equal(JOG_PERIOD_MS, 50);
  assert.equal(JOG_TIMEOUT_S, 0.15);
  const timers = fakeTimers();
  const calls = [];
  const stops = [];
  const r = new JogRepeater({ send: (c) => { calls.push(c); return Promise.resolve(); }, onStop: (why) => stops.push(why), timers });
  r.start("j0+");
  assert.deepEqual(calls, ["j0+"]);
  await settle();
  for (let i = 0; i < 10; i++) { timers.advance(50); await settle(); }
  assert.equal(calls.length, 11);
  r.stop("release");
  assert.equal(timers.count, 0);
  timers.advance(1000);
  await settle();
  assert.equal(calls.length, 11);
  assert.deepEqual(stops, ["release"]);
  assert.equal(r.active, false);
  r.stop("again");  // not holding: nothing
  assert.deepEqual(stops, ["release"]);
});

test("jog timer: never more than two calls outstanding, slow calls skip ticks", async () => {
  assert.equal(JOG_MAX_IN_FLIGHT, 2);
  const timers = fakeTimers();
  const pending = [];
  const r = new JogRepeater({ send: () => new Promise((res) => pending.push(res)), timers });
  r.start("x");
  timers.advance(200);  // four ticks: the first sends the second call, three are skipped
  assert.equal(pending.length, 2);
  assert.equal(r.skipped, 3);
  pending[0]();
  await settle();
  timers.advance(50);
  assert.equal(pending.length, 3);
  timers.advance(50);
  assert.equal(pending.length, 3);  // two outstanding again
  // released and pressed again while calls are outstanding: the new hold counts them too
  r.stop();
  r.start("y");
  assert.equal(pending.length, 3);
  pending[1]();
  await settle();
  timers.advance(50);
  assert.equal(pending.length, 4);
  timers.advance(50);
  assert.equal(pending.length, 4);
  // failures free their slot as answers do (a failed call of an ended hold changes nothing else)
  r.stop();
  pending[2]();
  pending[3]();
  await settle();
  assert.equal(r.inFlight, 0);
});

test("jog timer: an error ends the hold and is reported once; a late error of an ended hold is ignored", async () => {
  const timers = fakeTimers();
  const errors = [], stops = [];
  let fail = null;
  const r = new JogRepeater({
    send: () => new Promise((res, rej) => { fail = rej; }),
    onError: (e, c) => errors.push([e.message, c]), onStop: (w) => stops.push(w), timers,
  });
  r.start("a");
  fail(new Error("PermissionDenied"));
  await settle();
  assert.deepEqual(errors, [["PermissionDenied", "a"]]);
  assert.deepEqual(stops, ["error"]);
  assert.equal(r.active, false);
  assert.equal(timers.count, 0);
  // a hold released before its call fails: no error shown, nothing stopped twice
  r.start("b");
  r.stop("release");
  fail(new Error("late"));
  await settle();
  assert.equal(errors.length, 1);
  assert.deepEqual(stops, ["error", "release"]);
  // send throwing synchronously counts as a failed call
  const r2 = new JogRepeater({ send: () => { throw new Error("sync"); }, onError: (e) => errors.push([e.message]), timers });
  r2.start("c");
  await settle();
  assert.deepEqual(errors.at(-1), ["sync"]);
  assert.equal(r2.active, false);
  assert.throws(() => new JogRepeater({}), /send/);
});

test("jog timer: a new press replaces the held command", async () => {
  const timers = fakeTimers();
  const calls = [], stops = [];
  const r = new JogRepeater({ send: (c) => { calls.push(c); return Promise.resolve(); }, onStop: (w) => stops.push(w), timers });
  r.start("a");
  await settle();
  r.start("b");
  await settle();
  timers.advance(50);
  assert.deepEqual(calls, ["a", "b", "b"]);
  assert.deepEqual(stops, ["replaced"]);
  assert.equal(timers.count, 1);
  r.stop();
});

const unitEnum = [{ name: "implicit", value: 0 }, { name: "meter", value: 1 }, { name: "radian", value: 2 }];
const info = {
  joint_info: [
    { joint_identifier: { name: "shoulder" }, default_units: 2, joint_limits: { lower: -3, upper: 3, velocity: 1.5, reduced_velocity: 0.5 } },
    { joint_identifier: { name: "slide" }, default_units: 1, joint_limits: { lower: 0, upper: 0.5, velocity: 0.2, reduced_velocity: 0 } },
    { joint_identifier: { name: "" }, default_units: 2 },
  ],
};

test("joint model and rows: names, units, degrees with radians, limit bar and warning within 5 %", () => {
  const model = jointModel(info, unitEnum);
  assert.deepEqual(model.map((j) => [j.name, j.units, j.lower, j.upper, j.reducedVelocity]),
    [["shoulder", "radian", -3, 3, 0.5], ["slide", "meter", 0, 0.5, 0.2], ["joint_2", "radian", NaN, NaN, NaN]]);
  const rows = jointRows({ joint_position: new Float64Array([Math.PI / 4, 0.49, 1]), joint_velocity: new Float64Array([0.1, 0, 0]),
    joint_effort: new Float64Array(0) }, model);
  assert.deepEqual(rows.map((r) => r.name), ["shoulder", "slide", "joint_2"]);
  assert.equal(rows[0].text, "45.00° (0.7854 rad)");
  assert.equal(rows[1].text, "0.4900 m");
  assert.equal(rows[0].near, null);
  assert.equal(rows[1].near, "upper");      // 0.49 is within 5 % (0.025) of 0.5
  assert.equal(rows[2].fraction, null);     // no limits: no bar
  assert.equal(rows[0].velocity, "0.1000 rad/s");
  assert.equal(rows[0].effort, "");         // an effort array of the wrong length is not shown
  assert.ok(Math.abs(rows[0].fraction - (Math.PI / 4 + 3) / 6) < 1e-12);
  assert.deepEqual(jointRows(null), []);
  assert.deepEqual(jointModel(null), []);
});

test("limit warning: exactly at 5 % of the range, past a limit, and inside", () => {
  assert.equal(NEAR_LIMIT_FRACTION, 0.05);
  assert.equal(limitState(-2.7, -3, 3).near, "lower");   // 5 % of 6 = 0.3 from lower
  assert.ok(Math.abs(limitState(-2.7, -3, 3).fraction - 0.05) < 1e-12);
  assert.equal(limitState(-2.69, -3, 3).near, null);
  assert.equal(limitState(2.71, -3, 3).near, "upper");
  assert.deepEqual(limitState(4, -3, 3), { fraction: 1, near: "upper" });
  assert.deepEqual(limitState(-4, -3, 3), { fraction: 0, near: "lower" });
  assert.deepEqual(limitState(0, 1, 1), { fraction: null, near: null });
  assert.deepEqual(limitState(NaN, -1, 1), { fraction: null, near: null });
});

test("display units: degrees in and out for radians, metres as they are", () => {
  assert.ok(Math.abs(fromDisplay(90, "radian") - Math.PI / 2) < 1e-12);
  assert.ok(Math.abs(toDisplay(Math.PI, "radian") - 180) < 1e-12);
  assert.equal(fromDisplay(0.2, "meter"), 0.2);
  assert.equal(positionText(1, ""), "1.0000");
});

test("jog_joint velocity: only the held joint, a fraction of the reduced velocity limit", () => {
  const model = jointModel(info, unitEnum);
  assert.deepEqual(Array.from(jogVelocity(model, 0, 1, 0.5)), [0.25, 0, 0]);
  assert.deepEqual(Array.from(jogVelocity(model, 1, -1, 1)), [0, -0.2, 0]);  // reduced_velocity 0: the velocity limit
  assert.throws(() => jogVelocity(model, 2, 1, 0.5), /no velocity limit/);
  assert.throws(() => jogVelocity(model, 3, 1, 0.5), /no joint 3/);
  assert.throws(() => jogVelocity(model, 0, 2, 0.5), /direction/);
  assert.throws(() => jogVelocity(model, 0, 1, 1.5), /speed/);
  assert.throws(() => jogVelocity(model, 0, 1, 0), /speed/);
});

test("Cartesian jog velocity: one axis of chain 0", () => {
  const v = cartesianVelocity("z", -1, 0.5);
  assert.deepEqual([...v.keys()], [0]);
  assert.deepEqual(v.get(0), { angular: { x: 0, y: 0, z: 0 }, linear: { x: 0, y: 0, z: -0.5 * CARTESIAN_LINEAR_MPS } });
  assert.equal(cartesianVelocity("rx", 1, 1).get(0).angular.x, 0.5);
  assert.throws(() => cartesianVelocity("w", 1, 1), /axis/);
  assert.throws(() => cartesianVelocity("x", 0, 1), /direction/);
  assert.throws(() => cartesianVelocity("x", 1, 0), /speed/);
});

test("Cartesian jog: only NotImplementedError says the driver has none (refusals and other errors do not)", () => {
  assert.equal(isNotImplemented(Object.assign(new Error("x"), { errorName: "RobotRaconteur.NotImplementedError" })), true);
  assert.equal(isNotImplemented(Object.assign(new Error("x"), { errorName: "RobotRaconteur.PermissionDenied" })), false);
  assert.equal(isNotImplemented(Object.assign(new Error("x"), { errorName: "RobotRaconteur.InvalidOperation" })), false);
  assert.equal(isNotImplemented(new Error("NotImplementedError")), false);
  assert.equal(isNotImplemented(null), false);
});

const flagEnum = [{ name: "unknown", value: 0 }, { name: "error", value: 1 }, { name: "estop", value: 4 }, { name: "estop_released", value: 0x8000 },
  { name: "enabled", value: 0x20000 }, { name: "ready", value: 0x40000 }, { name: "homed", value: 0x80000 },
  { name: "homing_required", value: 0x100000 }, { name: "communication_failure", value: 0x200000 }];

test("status: flags as toned chips, modes by name, staleness after 1 s, capabilities", () => {
  assert.deepEqual(flagChips(flagEnum, 0x20000 | 0x40000 | 1), [{ name: "error", tone: "bad" }, { name: "enabled", tone: "good" }, { name: "ready", tone: "good" }]);
  assert.deepEqual(flagChips(flagEnum, 0n), []);
  assert.equal(flagTone("estop"), "bad");
  assert.equal(flagTone("estop_released"), "good");
  assert.equal(flagTone("communication_failure"), "bad");
  assert.equal(flagTone("homing_required"), "warn");
  assert.equal(flagTone("trajectory_queued"), "info");
  assert.equal(flagChips(flagEnum, 0x1000000).at(-1).name, "0x1000000");
  const modes = [{ name: "halt", value: 0 }, { name: "jog", value: 1 }];
  assert.equal(modeText(modes, 1), "jog");
  assert.equal(modeText(modes, 9), "9 (unknown)");
  assert.equal(modeText(modes, undefined), "");
  assert.equal(STALE_MS, 1000);
  assert.equal(isStale(1000, 1900), false);
  assert.equal(isStale(1000, 2001), true);
  assert.equal(isStale(0, 5), true);
  const caps = capabilitySet([{ name: "jog_command", value: 1 }, { name: "position_command", value: 4 }], 5);
  assert.deepEqual([...caps], ["jog_command", "position_command"]);
  assert.equal(capabilitySet([], undefined).size, 0);
});

test("access: URL with the device user, allows() by member and operation, the endpoint's answers", async () => {
  assert.equal(accessUrl("arm 1"), "api/devices/arm%201/access");
  assert.equal(accessUrl("arm", "bob&x"), "api/devices/arm/access?device_user=bob%26x");
  const viewer = { auth: true, user: "v", members: { robot_state: ["read"], jog_joint: ["read"] } };
  assert.equal(allows(viewer, "jog_joint", "call"), false);
  assert.equal(allows(viewer, "robot_state", "read"), true);
  assert.equal(allows({ members: null }, "anything", "call"), true);
  assert.equal(allows(null, "jog_joint", "call"), false);
  assert.equal(allows({ members: { command_mode: ["read", "write"] } }, "command_mode", "write"), true);
  assert.equal(mayLock({ ...viewer, lock: false }), false);
  assert.equal(mayLock({ ...viewer, lock: true }), true);
  assert.equal(mayLock({ auth: false, members: null, lock: null }), true);  // nothing checked
  assert.equal(mayLock(viewer), true);  // a gateway that does not say: its refusal decides
  assert.equal(mayLock(null), false);
  const reply = (status, body) => async (url) => ({ status, ok: status < 300, json: async () => body, url });
  assert.deepEqual(await fetchAccess("arm", null, reply(200, viewer)), viewer);
  assert.equal((await fetchAccess("arm", null, reply(404, null))).members, null);
  await assert.rejects(fetchAccess("arm", null, reply(500, null)), /access to arm: HTTP 500/);
  await assert.rejects(fetchAccess("arm", null, reply(200, { members: 3 })), /not an access answer/);
  let asked = null;
  await fetchAccess("arm", "alice", async (url) => { asked = url; return { status: 200, ok: true, json: async () => ({ members: null }) }; });
  assert.equal(asked, "api/devices/arm/access?device_user=alice");
});

test("keyboard shortcuts and lock text", () => {
  assert.deepEqual(jogKey("q", 3), { joint: 0, direction: 1 });
  assert.deepEqual(jogKey("D", 3), { joint: 2, direction: -1 });
  assert.equal(jogKey("r", 3), null);   // a fourth joint the robot does not have
  assert.equal(jogKey("Shift", 7), null);
  assert.equal(jogKeysText(1), "W/S");
  assert.equal(jogKeysText(7), "");
  assert.equal(locksText([]), "");
  assert.equal(locksText([{ path: "robot", user: "alice", kind: "monitor" }, { path: "robot", user: null, kind: "monitor" }]),
    "monitor lock on robot by alice; monitor lock on robot");
});
