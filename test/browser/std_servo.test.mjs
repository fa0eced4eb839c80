// The servo and actuator panels (issue 54) on motion devices served by the official library
// (test/browser/devices/servo.py: a two-axis stage that keeps moving at its last velocity command until
// halt(), and a belt conveyor that runs at its last command until its mode is halt) behind rr-gateway
// with logins (alice: operator, bob: viewer): state, units and info as the device sent them; holding a
// servo axis's + streams velocity commands (the mode set to velocity_command first) and the stage
// moves; the release calls halt() and nothing moves after it; Run (hold) drives the conveyor and the
// release sets its mode to halt; a viewer sees no control; the page's connection killed mid-hold: the
// gateway's standard servo rules halt the stage when its command stream goes silent (this check fails on
// a gateway without them); a servo without servo_state falls back to the generic view. No page error.

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import fs from "node:fs";
import { launchChromium, waitFor, TcpRelay } from "./harness.mjs";
import { startDevice, screenshot } from "./std_support.mjs";
import { gatewayWithLogins, loggedInPage, panelOf } from "./std_sensor_support.mjs";

const STOP_BOUND_S = 1.0;      // the page's stop reaching the device after the release (tens of ms typically)
const GATEWAY_BOUND_S = 2.0;   // the gateway's stop after the page's connection died: its 0.5 s silence bound, detection, delivery
const PERIOD_S = 0.02;         // the sim's loop step
let motion, oldMotion, gw, browser, operator;
const pageErrors = [];
const log = { calls: [], moved: [], ticks: [] };

before(async () => {
  motion = await startDevice("servo.py", ["--max-lifetime", "280"]);
  motion.child.lines.on("line", (line) => {
    try {
      const v = JSON.parse(line);
      if (typeof v.call === "string") log.calls.push(v);
      else if (typeof v.moved === "string") log.moved.push(v);
      else if (typeof v.tick === "number") log.ticks.push(v.tick);
    } catch { /* not a log line */ }
  });
  oldMotion = await startDevice("servo.py", ["--without-member", "servo_state", "--max-lifetime", "280"]);
  gw = await gatewayWithLogins({ stage: motion.info.urls.servo, belt: motion.info.urls.conveyor, oldstage: oldMotion.info.urls.servo });
  browser = await launchChromium();
  operator = await loggedInPage(browser, gw.gateway.base, "alice", "stage", pageErrors);
});

after(async () => {
  await browser?.close();
  await gw?.gateway.child.stop();
  await motion?.child.stop();
  await oldMotion?.child.stop();
  if (gw?.tmp) fs.rmSync(gw.tmp, { recursive: true, force: true });
});

const lastCall = (name, from, value) => log.calls.filter((c) => c.call === name && c.t >= from && (value === undefined || c.value === value)).at(-1) ?? null;
const movedAfter = (what, t) => log.moved.filter((m) => m.moved === what && m.t > t);
const logUntil = (t, what) => waitFor(() => log.ticks.some((x) => x > t), `${what}: the device's log up to ${t.toFixed(3)}`, 30000, 20);

async function open(page, device, name) {
  await page.goto(`${page.url().replace(/#.*$/, "")}#/${device}`);
  const p = panelOf(page, device, name);
  await p.waitFor({ timeout: 60000 });
  await waitFor(async () => (await p.getAttribute("data-ready")) === "true", `${device} panel ready`, 40000);
  return p;
}

/** Presses `button` and waits until the panel's hold started. */
async function holdDown(page, p, button) {
  await waitFor(async () => !(await button.isDisabled()), "jog enabled", 15000);
  const holds = Number((await p.getAttribute("data-holds")) ?? 0);
  await button.hover({ timeout: 20000 });
  await page.mouse.down();
  await waitFor(async () => Number((await p.getAttribute("data-holds")) ?? 0) > holds, "a hold started", 20000, 20);
}

/** The stop `call` (with `value`) reached the device within `bound` of `since`, and nothing of `what` moved after it. */
async function stoppedBy(call, value, since, bound, what, label) {
  const stop = await waitFor(() => lastCall(call, since, value), `${label}: ${call} after it`, 20000, 10);
  console.log(`# ${label}: ${call} reached the device ${((stop.t - since) * 1000).toFixed(0)} ms after`);
  assert.ok(stop.t - since < bound, `${label}: ${call} came ${(stop.t - since).toFixed(3)} s after`);
  await logUntil(stop.t + 0.3, label);
  assert.deepEqual(movedAfter(what, stop.t + PERIOD_S), [], `${label}: moved after ${call}`);
  return stop;
}

test("servo: state, axes with units and servo_info as the device sent them", async () => {
  const p = await open(operator, "stage", "servo");
  await waitFor(async () => (await p.getAttribute("data-mode")) === "halt", "mode halt");
  assert.equal(await p.getAttribute("data-flags"), "ready | streaming | enabled");
  const cell = (axis, cls) => p.locator(`tr[data-axis="${axis}"] .${cls}`);
  await waitFor(async () => (await cell(1, "servo-position").textContent()) === "0.05 m", "axis 1 position");
  assert.equal(await cell(0, "servo-position").textContent(), "0.1 m");
  assert.equal(await cell(0, "servo-velocity").textContent(), "0 m/s");
  assert.equal(await cell(0, "servo-effort").textContent(), "1.5 N");
  assert.equal(await cell(1, "servo-effort").textContent(), "-0.5 N");
  const info = (key) => p.locator(`.servo-info dd[data-row="${key}"]`).textContent();
  assert.equal(await info("servo_type"), "prismatic_electric");
  assert.equal(await info("capabilities"), "position_command | velocity_command | trapezoidal_command");
  assert.equal(await info("velocity"), "-0.05 … 0.05, -0.05 … 0.05");
  assert.deepEqual(pageErrors, []);
});

test("servo: holding axis 0 + streams velocity commands and the stage moves; the release halts it", async () => {
  const p = await open(operator, "stage", "servo");
  const from = Date.now() / 1000;
  await holdDown(operator, p, p.locator('button.jog[data-axis="0"][data-dir="1"]'));
  assert.ok(lastCall("mode", from - 1, 2), "the mode was set to velocity_command (2) first");
  await waitFor(() => movedAfter("servo", from).length > 5, "the stage moving", 20000, 10);
  const moving = movedAfter("servo", from);
  assert.ok(moving.at(-1).position[0] > moving[0].position[0], "axis 0 moves +");
  assert.equal(moving.at(-1).position[1], 0.05, "axis 1 stays");
  await screenshot(p, "dashboard-servo.png");
  const released = Date.now() / 1000;
  await operator.mouse.up();
  await stoppedBy("halt", undefined, released, STOP_BOUND_S, "servo", "servo release");
  assert.equal(await p.getAttribute("data-hold-stop"), "release");
  assert.deepEqual(pageErrors, []);
});

test("actuator: the conveyor's state, Run (hold) drives it, the release sets its mode to halt", async () => {
  const p = await open(operator, "belt", "actuator");
  const row = (key) => p.locator(`dd[data-row="${key}"]`);
  await waitFor(async () => (await row("command-0").count()) === 1 && (await row("command-0").textContent()) === "0 m/s", "command 0 m/s");
  assert.equal(await row("actuator_state_flags").textContent(), "ready | enabled");
  await waitFor(async () => (await row("actuator_mode").textContent()) === "halt", "mode halt");
  assert.equal(await row("actuator_type").textContent(), "conveyor");
  assert.equal(await row("command_units").textContent(), "m/s");
  await p.locator('input[name="actuator-command"]').fill("0.3");
  const from = Date.now() / 1000;
  await holdDown(operator, p, p.locator('button[data-action="run"]'));
  await waitFor(() => movedAfter("conveyor", from).some((m) => m.speed === 0.3), "the belt running at 0.3 m/s", 20000, 10);
  assert.ok(lastCall("actuator_mode", from - 1, 2), "the mode was set to normal (2) first");
  await waitFor(async () => (await row("command-0").textContent()) === "0.3 m/s", "0.3 m/s shown");
  await screenshot(p, "dashboard-actuator.png");
  const released = Date.now() / 1000;
  await operator.mouse.up();
  await stoppedBy("actuator_mode", 0, released, STOP_BOUND_S, "conveyor", "conveyor release");
  await waitFor(async () => (await row("actuator_mode").textContent()) === "halt", "mode halt shown");
  assert.deepEqual(pageErrors, []);
});

test("a viewer sees servo and actuator state and no control; a servo without servo_state falls back", async () => {
  const page = await loggedInPage(browser, gw.gateway.base, "bob", "stage", pageErrors);
  const p = await open(page, "stage", "servo");
  assert.equal(await p.getAttribute("data-access"), "checked");
  await waitFor(async () => (await p.getAttribute("data-mode")) !== null, "state shown");
  assert.equal(await p.locator("button, select, input").count(), 0);
  const a = await open(page, "belt", "actuator");
  assert.equal(await a.locator("button, select, input").count(), 0);
  await page.goto(`${gw.gateway.base}/#/oldstage`);
  const old = panelOf(page, "oldstage", "servo");
  await old.waitFor({ timeout: 60000 });
  assert.equal(await old.getAttribute("data-fallback"), "true");
  await page.locator('.device-view[data-device="oldstage"] .member[data-member="servo_info"]').first().waitFor({ timeout: 60000 });
  await page.context().close();
  assert.deepEqual(pageErrors, []);
});

test("servo: the page's connection killed mid-hold: the gateway halts the stage when its command stream goes silent", async () => {
  const relay = new TcpRelay(gw.gateway.port);
  await relay.listen();
  let page = null, dropped = false;
  try {
    page = await loggedInPage(browser, `http://127.0.0.1:${relay.port}`, "alice", "stage", pageErrors);
    const p = await open(page, "stage", "servo");
    const from = Date.now() / 1000;
    await holdDown(page, p, p.locator('button.jog[data-axis="1"][data-dir="1"]'));
    await waitFor(() => movedAfter("servo", from).length > 3, "the stage moving", 20000, 10);
    const killed = Date.now() / 1000;
    await relay.drop();
    dropped = true;
    await stoppedBy("halt", undefined, killed, GATEWAY_BOUND_S, "servo", "connection killed");
  } finally {
    if (!dropped) await relay.drop();
    await page?.mouse.up().catch(() => {});
    await page?.context().close();
  }
});
