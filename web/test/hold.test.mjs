// The shared hold-to-run helper (src/hold/hold_to_run.js) with the robot's JogRepeater and the tool's
// ToolHold as its motions, and the gamepad input (src/hold/gamepad.js) with a stand-in
// navigator.getGamepads and fake timers: what starts a hold, every way it ends (release, blur, page
// hide, hidden tab, session closed, dispose), the gamepad armed only at rest, released when the stick
// comes back or the gamepad is lost, and never restarted by a stick still pushed after a hold ended
// elsewhere.
import { test } from "node:test";
import assert from "node:assert/strict";
import { HoldToRun } from "../src/hold/hold_to_run.js";
import { GamepadFollower, heldBinding, atRest, deflection, jointBindings, inputName, HOLD_AT, REST_BELOW } from "../src/hold/gamepad.js";
import { JogRepeater } from "../src/robot/jog_repeater.js";
import { ToolHold } from "../src/tool/tool_state.js";

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

/** A window, document and RR client stand-in. */
function page() {
  const win = new EventTarget();
  const doc = new EventTarget();
  doc.visibilityState = "visible";
  const closers = [];
  const client = { onClose: (fn) => { closers.push(fn); return () => closers.splice(closers.indexOf(fn), 1); }, close: () => closers.forEach((f) => f()) };
  return { win, doc, client, closers };
}

/** A HoldToRun over a JogRepeater that records its calls. */
function robotHold(extra = {}) {
  const timers = fakeTimers();
  const calls = [], stops = [], starts = [];
  const p = page();
  let hold;
  const repeater = new JogRepeater({ send: (c) => { calls.push(c); return Promise.resolve(); }, onStop: (r) => hold.stopped(r), timers });
  hold = new HoldToRun({ motion: repeater, client: p.client, win: p.win, doc: p.doc,
    onStart: (c, source) => starts.push([c, source]), onStop: (r) => stops.push(r), ...extra });
  return { hold, repeater, timers, calls, stops, starts, ...p };
}

test("hold-to-run: a press starts the robot's jog; every way the page loses the operator ends it", async () => {
  for (const [why, end] of [
    ["release", (t) => t.hold.release("release")],
    ["blur", (t) => t.win.dispatchEvent(new Event("blur"))],
    ["pagehide", (t) => t.win.dispatchEvent(new Event("pagehide"))],
    ["hidden", (t) => { t.doc.visibilityState = "hidden"; t.doc.dispatchEvent(new Event("visibilitychange")); }],
    ["session closed", (t) => t.client.close()],
    ["dispose", (t) => t.hold.dispose()],
  ]) {
    const t = robotHold();
    await t.hold.press(() => "j1+", "pointer");
    assert.equal(t.hold.active, true, why);
    assert.deepEqual(t.starts, [["j1+", "pointer"]]);
    t.timers.advance(100);
    await settle();
    const sent = t.calls.length;
    assert.ok(sent >= 2, `${why}: calls while held`);
    end(t);
    assert.equal(t.hold.active, false, why);
    assert.deepEqual(t.stops, [why]);
    t.timers.advance(1000);
    await settle();
    assert.equal(t.calls.length, sent, `${why}: a call after the hold ended`);
  }
});

test("hold-to-run: a visible tab does not end it; after dispose nothing listens", async () => {
  const t = robotHold();
  await t.hold.press(() => "j1+");
  t.doc.dispatchEvent(new Event("visibilitychange"));  // still visible
  assert.equal(t.hold.active, true);
  t.hold.dispose();
  assert.equal(t.closers.length, 0);
  assert.equal(await t.hold.press(() => "j1+"), false, "a press after dispose");
  assert.equal(t.hold.active, false);
});

test("hold-to-run: a command that cannot be made starts nothing; let go while preparing undoes it", async () => {
  const errors = [];
  const t = robotHold({ onError: (e) => errors.push(e.message) });
  assert.equal(await t.hold.press(() => { throw new Error("no joints"); }), false);
  assert.deepEqual(errors, ["no joints"]);
  assert.equal(t.calls.length, 0);

  let unlock = 0, letGo;
  const gate = new Promise((r) => { letGo = r; });
  const u = robotHold({ prepare: async () => { await gate; return true; }, cancelled: () => unlock++ });
  const pressed = u.hold.press(() => "j2-");
  u.hold.release("release");  // before the lock came
  letGo();
  assert.equal(await pressed, false);
  assert.equal(unlock, 1);
  assert.equal(u.calls.length, 0);
  const refused = robotHold({ prepare: async () => false });
  assert.equal(await refused.hold.press(() => "j2-"), false);
  assert.equal(refused.calls.length, 0);
});

test("hold-to-run: the tool's ToolHold as the motion: halt() once the call answered, on every end", async () => {
  const p = page();
  const order = [];
  let run;
  const tool = new ToolHold({ halt: async () => { order.push("halt"); }, onStop: (r) => run.stopped(r) });
  const stops = [];
  run = new HoldToRun({ motion: { start: (c) => tool.start(c.name, c.call), stop: (r) => tool.stop(r), get active() { return tool.active; } },
    client: p.client, win: p.win, doc: p.doc, onStop: (r) => stops.push(r) });
  await run.press(() => ({ name: "close", call: async () => { order.push("close"); } }));
  await settle();
  p.win.dispatchEvent(new Event("blur"));
  await settle();
  assert.deepEqual(order, ["close", "halt"]);
  assert.deepEqual(stops, ["blur"]);
  // replaced by another hold: one halt in between, no onStop for the replaced hold
  await run.press(() => ({ name: "open", call: async () => { order.push("open"); } }));
  await run.press(() => ({ name: "close", call: async () => { order.push("close"); } }));
  await settle();
  run.release("release");
  await settle();
  assert.deepEqual(order, ["close", "halt", "open", "halt", "close", "halt"]);
  assert.deepEqual(stops, ["blur", "release"]);
});

test("hold-to-run: buttons: pointerdown holds, pointerup releases, forgotten buttons no longer hold", async () => {
  const t = robotHold();
  const button = new EventTarget();
  button.classList = { set: new Set(), add(c) { this.set.add(c); }, remove(c) { this.set.delete(c); }, contains(c) { return this.set.has(c); } };
  button.setPointerCapture = () => {};
  const ev = (type) => Object.assign(new Event(type), { button: 0, pointerId: 1 });
  t.hold.button(button, () => "j3+");
  button.dispatchEvent(ev("pointerdown"));
  await settle();
  assert.equal(t.hold.active, true);
  assert.equal(button.classList.contains("held"), true);
  button.dispatchEvent(ev("pointerup"));
  assert.equal(t.hold.active, false);
  assert.equal(button.classList.contains("held"), false);
  assert.deepEqual(t.stops, ["release"]);
  t.hold.forgetButtons([button]);
  button.dispatchEvent(ev("pointerdown"));
  await settle();
  assert.equal(t.hold.active, false);
});

// ---- gamepad ----

/** A standard-mapping gamepad stand-in. */
function pad(index = 0) {
  return { index, id: "Xbox 360 Controller (STANDARD GAMEPAD)", connected: true, mapping: "standard",
    axes: [0, 0, 0, 0], buttons: Array.from({ length: 17 }, () => ({ pressed: false, value: 0 })) };
}

test("gamepad bindings: joints on sticks, d-pad and shoulders; the most deflected past half holds", () => {
  const b = jointBindings(3, (i, d) => `${i}${d > 0 ? "+" : "-"}`);
  assert.deepEqual(b.map((x) => x.id), ["joint 1 +", "joint 1 −", "joint 2 +", "joint 2 −", "joint 3 +", "joint 3 −"]);
  assert.equal(jointBindings(9).length, 14, "seven joints at most");
  const p = pad();
  assert.equal(heldBinding(p, b), null);
  assert.equal(atRest(p, b), true);
  p.axes[1] = -0.49;  // left stick up, not yet half
  assert.equal(heldBinding(p, b), null);
  assert.equal(atRest(p, b), false);
  p.axes[1] = -HOLD_AT;
  assert.equal(heldBinding(p, b).id, "joint 2 +");
  assert.equal(heldBinding(p, b).command, "1+");
  p.axes[0] = -0.9;  // more to the left than up
  assert.equal(heldBinding(p, b).id, "joint 1 −");
  p.axes[3] = 1;
  assert.equal(heldBinding(p, b).id, "joint 3 −");
  assert.equal(deflection(p, { axis: 3, sign: -1 }), 0);
  const q = pad();
  q.axes[0] = REST_BELOW - 0.01;
  assert.equal(atRest(q, b), true);
  const six = jointBindings(6);
  q.buttons[14] = { pressed: true, value: 1 };
  assert.equal(heldBinding(q, six).id, "joint 6 −");
  assert.equal(atRest(q, six), false);
  assert.equal(inputName(six[2]), "left stick y ↑");
  assert.equal(inputName(six[0]), "left stick x →");
  assert.equal(inputName(six[11]), "d-pad left");
});

/** A follower over a stand-in getGamepads, with a HoldToRun over a JogRepeater. */
function followed({ refuse = false } = {}) {
  const t = robotHold();
  const pads = [pad()];
  const states = [];
  const win = new EventTarget();
  const follower = new GamepadFollower({
    bindings: () => jointBindings(3, (i, d) => () => `j${i + 1}${d > 0 ? "+" : "-"}`),
    onHold: (b) => { if (refuse) return false; t.hold.press(b.command, "gamepad"); return true; },
    onRelease: (reason) => t.hold.release(reason),
    onStatus: (s) => states.push(s.state === "holding" ? `holding ${s.binding.id}` : s.state),
    getGamepads: () => pads, win, timers: t.timers,
  });
  t.hold.follow(follower);
  return { ...t, pads, states, follower, padWin: win };
}

test("gamepad: armed at rest, a stick holds the jog, back to the centre releases it", async () => {
  const t = followed();
  t.follower.start();
  assert.deepEqual(t.states, ["armed"]);
  t.pads[0].axes[1] = -1;  // left stick up: joint 2 +
  t.timers.advance(20);
  await settle();
  assert.equal(t.hold.active, true);
  assert.equal(t.repeater.command, "j2+");
  t.pads[0].axes[1] = -0.3;  // on its way back, still past rest: held (no flicker)
  t.timers.advance(20);
  assert.equal(t.hold.active, true);
  t.pads[0].axes[1] = -0.05;
  t.timers.advance(20);
  assert.equal(t.hold.active, false);
  assert.deepEqual(t.stops, ["gamepad released"]);
  assert.deepEqual(t.states, ["armed", "holding joint 2 +", "armed"]);
  // another stick, then a switch to a more deflected one replaces the motion without a stop
  t.pads[0].axes[0] = 1;
  t.timers.advance(20);
  await settle();
  assert.equal(t.repeater.command, "j1+");
  t.pads[0].axes[3] = -1; t.pads[0].axes[0] = 0.6;
  t.timers.advance(20);
  await settle();
  assert.equal(t.repeater.command, "j3+");
  assert.deepEqual(t.stops, ["gamepad released"]);
  t.follower.stop();
  assert.equal(t.hold.active, false);
  assert.deepEqual(t.stops, ["gamepad released", "gamepad off"]);
  assert.equal(t.timers.count, 0);
});

test("gamepad: a stick pushed when following starts never moves until it was at rest", async () => {
  const t = followed();
  t.pads[0].axes[0] = 1;
  t.follower.start();
  for (let i = 0; i < 10; i++) t.timers.advance(20);
  await settle();
  assert.equal(t.hold.active, false);
  assert.equal(t.calls.length, 0);
  assert.equal(t.follower.state, "unarmed");
  t.pads[0].axes[0] = 0;
  t.timers.advance(20);
  assert.equal(t.follower.state, "armed");
  t.pads[0].axes[0] = 1;
  t.timers.advance(20);
  await settle();
  assert.equal(t.hold.active, true);
});

test("gamepad: lost (disconnected event, or gone from getGamepads) releases at once; back, it must be at rest first", async () => {
  for (const lose of [(t) => { t.padWin.dispatchEvent(Object.assign(new Event("gamepaddisconnected"), { gamepad: { index: 0 } })); },
    (t) => { t.pads.length = 0; t.timers.advance(20); },
    (t) => { t.pads[0] = { ...t.pads[0], connected: false }; t.timers.advance(20); }]) {
    const t = followed();
    t.follower.start();
    t.pads[0].axes[1] = 1;
    t.timers.advance(20);
    await settle();
    assert.equal(t.hold.active, true);
    lose(t);
    assert.equal(t.hold.active, false);
    assert.deepEqual(t.stops, ["gamepad lost"]);
    assert.equal(t.follower.state, "none");
    // it comes back with the stick still pushed: nothing moves
    const back = pad(); back.axes[1] = 1;
    t.pads.length = 0; t.pads.push(back);
    for (let i = 0; i < 5; i++) t.timers.advance(20);
    await settle();
    assert.equal(t.hold.active, false);
    assert.equal(t.follower.state, "unarmed");
    t.follower.stop();
  }
});

test("gamepad: a hold ended elsewhere (blur, a refused call) is not restarted by the stick still pushed", async () => {
  const t = followed();
  t.follower.start();
  t.pads[0].axes[1] = 1;
  t.timers.advance(20);
  await settle();
  assert.equal(t.hold.active, true);
  t.win.dispatchEvent(new Event("blur"));
  assert.equal(t.hold.active, false);
  for (let i = 0; i < 10; i++) t.timers.advance(20);
  await settle();
  assert.equal(t.hold.active, false, "the stick still pushed restarted the jog");
  assert.equal(t.follower.state, "unarmed");
  t.pads[0].axes[1] = 0;
  t.timers.advance(20);
  t.pads[0].axes[1] = 1;
  t.timers.advance(20);
  await settle();
  assert.equal(t.hold.active, true);
  t.follower.stop();

  // the panel refuses (robot not in jog mode): unarmed until rest, nothing held
  const r = followed({ refuse: true });
  r.follower.start();
  r.pads[0].axes[0] = 1;
  r.timers.advance(20);
  assert.equal(r.hold.active, false);
  assert.equal(r.follower.state, "unarmed");
  r.follower.stop();
});

import { streamHold } from "../src/hold/stream_hold.js";

test("stream hold: commands streamed every period while held; the device's stop once at every end; none when not prepared", async () => {
  const timers = fakeTimers();
  const p = page();
  const sent = [], stops = [], ends = [];
  let prepared = true;
  const hold = streamHold({ send: (v) => { sent.push(v); }, stopDevice: async () => { stops.push("stop"); }, prepare: async () => prepared,
    onStop: (r) => ends.push(r), client: p.client, win: p.win, doc: p.doc, timers });
  await hold.press(() => "v+");
  for (let i = 0; i < 4; i++) { timers.advance(50); await settle(); }
  assert.equal(sent.length, 5);
  hold.release("release");
  await settle();
  assert.deepEqual(stops, ["stop"]);
  assert.deepEqual(ends, ["release"]);
  timers.advance(500);
  assert.equal(sent.length, 5, "a command after the hold ended");
  // a send that throws (the wire not connected) ends the hold, and the device is stopped anyway
  const errors = [];
  const failing = streamHold({ send: () => { throw new Error("wire velocity_command is not connected"); }, stopDevice: async () => { stops.push("stop2"); },
    onError: (e, what) => errors.push(`${what}: ${e.message}`), win: p.win, doc: p.doc, timers });
  await failing.press(() => "v+");
  await settle();
  assert.equal(failing.active, false);
  assert.deepEqual(errors, ["send: wire velocity_command is not connected"]);
  assert.deepEqual(stops, ["stop", "stop2"]);
  // not prepared (the mode could not be set): nothing sent, nothing stopped
  prepared = false;
  assert.equal(await hold.press(() => "v+"), false);
  assert.equal(sent.length, 5);
  assert.deepEqual(stops, ["stop", "stop2"]);
});
