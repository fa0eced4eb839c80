// The joystick panel and the browser's gamepad as a hold-to-run input (issue 54), on devices served by
// the official library behind rr-gateway with logins (alice: operator, bob: viewer):
//   * test/browser/devices/joystick.py (a standard Joystick, its state held on command): the axes,
//     buttons, hat, gamepad state and joystick_info shown equal what the device sent; the values move
//     with its pattern; Rumble reaches it from the operator's page only; a joystick without
//     joystick_state falls back to the generic view;
//   * test/browser/devices/sim_tool.py (a standard Tool): a gamepad the page sees through
//     navigator.getGamepads (faked with addInitScript, as Chromium has no gamepad in a headless run)
//     holds Close while A is pressed, and the tool gets halt() when A is let go and when the gamepad is
//     lost; a button already pressed when the gamepad is switched on moves nothing until let go.
// No page error anywhere. Screenshot to $RR_ARTIFACTS (docs/img with RR_DOCS_SCREENSHOTS=1).

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import fs from "node:fs";
import { launchChromium, waitFor } from "./harness.mjs";
import { startDevice, screenshot } from "./std_support.mjs";
import { gatewayWithLogins, command, panelOf } from "./std_sensor_support.mjs";

let joystick, oldJoystick, tool, gw, browser;
const pageErrors = [];
const rumbles = [];
const toolLog = { calls: [], moves: [], ticks: [] };
const HALT_BOUND_S = 1.0;  // halt() reaching the tool after the gamepad let go (tens of ms typically; a loaded CI machine delays delivery)

before(async () => {
  joystick = await startDevice("joystick.py", ["--max-lifetime", "250"], { stdin: "pipe" });
  joystick.child.lines.on("line", (line) => {
    try { const v = JSON.parse(line); if (v.call === "rumble") rumbles.push(v); } catch { /* not a log line */ }
  });
  oldJoystick = await startDevice("joystick.py", ["--without-member", "joystick_state", "--max-lifetime", "250"]);
  tool = await startDevice("sim_tool.py", ["--enabled", "--log-motion", "--max-lifetime", "250"]);
  tool.child.lines.on("line", (line) => {
    try {
      const v = JSON.parse(line);
      if (typeof v.call === "string") toolLog.calls.push(v);
      else if (typeof v.tool === "number") toolLog.moves.push(v);
      else if (typeof v.tick === "number") toolLog.ticks.push(v.tick);
    } catch { /* not a log line */ }
  });
  gw = await gatewayWithLogins({ pad: joystick.info.url, oldpad: oldJoystick.info.url, gripper: tool.info.url });
  browser = await launchChromium();
});

after(async () => {
  await browser?.close();
  await gw?.gateway.child.stop();
  for (const d of [joystick, oldJoystick, tool]) await d?.child.stop();
  if (gw?.tmp) fs.rmSync(gw.tmp, { recursive: true, force: true });
});

// A gamepad the page reads through navigator.getGamepads: window.__pads, changed by the test.
const FAKE_GAMEPADS = () => {
  const buttons = () => Array.from({ length: 17 }, () => ({ pressed: false, touched: false, value: 0 }));
  window.__pads = [{ index: 0, id: "Test pad (STANDARD GAMEPAD Vendor: 045e Product: 028e)", connected: true, mapping: "standard",
    timestamp: 0, axes: [0, 0, 0, 0], buttons: buttons() }];
  window.__press = (i, pressed) => { window.__pads[0].buttons[i] = { pressed, touched: pressed, value: pressed ? 1 : 0 }; window.__pads[0].timestamp++; };
  Object.defineProperty(Navigator.prototype, "getGamepads", { configurable: true, value: () => window.__pads.slice() });
};

/** A page logged in as `user` on `device`, optionally with the fake gamepad. */
async function loggedIn(user, device, { gamepad = false } = {}) {
  const context = await browser.newContext({ viewport: { width: 1280, height: 1000 } });
  if (gamepad) await context.addInitScript(FAKE_GAMEPADS);
  const page = await context.newPage();
  page.on("pageerror", (e) => pageErrors.push(`${user}: ${e}`));
  await page.goto(`${gw.gateway.base}/#/${device}`);
  await page.waitForURL(/\/login\.html/, { timeout: 20000 });
  await page.fill("#login-username", user);
  await page.fill("#login-password", `${user}-pw`);
  await page.click("#login-submit");
  await page.waitForURL((u) => !/login\.html/.test(String(u)), { timeout: 20000 });
  await page.goto(`${gw.gateway.base}/#/${device}`);
  return page;
}

const HELD = { axes: [16384, -32768, 0, 32767], buttons: [1, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0], hats: [2] };

test("joystick: axes, buttons, hat, gamepad state and info as the device sent them; live; Rumble for the operator", async () => {
  await command(joystick, { hold: HELD }, "held");
  const page = await loggedIn("alice", "pad");
  const p = panelOf(page, "pad", "joystick");
  await p.waitFor({ timeout: 60000 });
  const axis = (i) => p.locator(`tr[data-axis="${i}"] .joystick-axis-value`);
  await waitFor(async () => (await axis(3).count()) === 1 && (await axis(3).textContent()) === "32767 (100%)", "held axes shown", 30000);
  assert.deepEqual(await Promise.all([0, 1, 2, 3].map((i) => axis(i).textContent())), ["16384 (50%)", "-32768 (-100%)", "0 (0%)", "32767 (100%)"]);
  assert.equal(await p.getAttribute("data-pressed"), "0,3");
  assert.equal(await p.locator(".joystick-buttons .chip").count(), 12);
  assert.equal(await p.locator('[data-hat="0"]').textContent(), "hat 0: hat_right");
  const row = (key) => p.locator(`dd[data-row="${key}"]`);
  await waitFor(async () => (await row("gamepad-buttons").count()) === 1, "gamepad state shown");
  assert.equal(await row("left").textContent(), "(50%, -100%)");
  assert.equal(await row("right").textContent(), "(0%, 100%)");
  assert.equal(await row("gamepad-buttons").textContent(), "A | Y | dpad_right");
  await waitFor(async () => (await row("counts").count()) === 1, "joystick_info shown");
  assert.equal(await row("counts").textContent(), "4 axes, 12 buttons, 1 hats");
  assert.equal(await row("capabilities").textContent(), "rumble | standard_gamepad");
  assert.equal(await row("usb").textContent(), "045e:028e v0110");
  await screenshot(p, "dashboard-joystick.png");

  // the pattern again: the axes and the pressed button move
  await command(joystick, { resume: true }, "resumed");
  await waitFor(async () => (await axis(3).textContent()) === "0 (0%)", "right stick y back at 0 (the pattern)");
  const first = await axis(0).textContent();
  await waitFor(async () => (await axis(0).textContent()) !== first, "axis 0 moving");
  await waitFor(async () => (await p.getAttribute("data-pressed")) !== "0,3", "pressed buttons follow the pattern");

  await waitFor(async () => (await p.getAttribute("data-ready")) === "true", "access known");
  await p.locator('button[data-action="rumble"]').click();
  await waitFor(() => rumbles.length === 1, "rumble() reached the joystick");
  assert.deepEqual(rumbles[0], { call: "rumble", intensity: 0.5, duration: 0.5 });
  await page.context().close();
  assert.deepEqual(pageErrors, []);
});

test("joystick: a viewer sees the values and no control; a joystick without joystick_state falls back", async () => {
  const page = await loggedIn("bob", "pad");
  const p = panelOf(page, "pad", "joystick");
  await p.waitFor({ timeout: 60000 });
  await waitFor(async () => (await p.getAttribute("data-ready")) === "true", "access known", 30000);
  await waitFor(async () => Number(await p.getAttribute("data-samples")) > 0, "states shown");
  assert.equal(await p.getAttribute("data-access"), "checked");
  assert.equal(await p.locator("button, input").count(), 0);

  await page.goto(`${gw.gateway.base}/#/oldpad`);
  const old = panelOf(page, "oldpad", "joystick");
  await old.waitFor({ timeout: 60000 });
  assert.equal(await old.getAttribute("data-fallback"), "true");
  await page.locator('.device-view[data-device="oldpad"] .member[data-member="gamepad_state"]').first().waitFor({ timeout: 60000 });
  await page.context().close();
  assert.deepEqual(pageErrors, []);
});

const lastCall = (name, from) => toolLog.calls.filter((c) => c.call === name && c.t >= from).at(-1) ?? null;

/** Asserts halt() reached the tool after `since` (s) within the bound, and no step moved after it. */
async function haltedAfter(since, what) {
  const halt = await waitFor(() => lastCall("halt", since), `${what}: halt() reached the tool`, 20000, 10);
  console.log(`# ${what}: halt() ${((halt.t - since) * 1000).toFixed(0)} ms after`);
  assert.ok(halt.t - since < HALT_BOUND_S, `${what}: halt() came ${(halt.t - since).toFixed(3)} s after`);
  await waitFor(() => toolLog.ticks.some((x) => x > halt.t + 0.3), `${what}: the tool's log past the halt`, 30000, 20);
  assert.deepEqual(toolLog.moves.filter((m) => m.tool > halt.t + 0.02), [], `${what}: the fingers moved after halt()`);
}

test("gamepad: A held closes the gripper through hold-to-run; let go, or the gamepad lost, halts it", async () => {
  const page = await loggedIn("alice", "gripper", { gamepad: true });
  const p = panelOf(page, "gripper", "tool");
  await p.waitFor({ timeout: 60000 });
  await waitFor(async () => (await p.getAttribute("data-ready")) === "true", "tool panel ready", 40000);
  const pad = p.locator(".gamepad-control");
  // A already pressed when the gamepad is switched on: nothing moves until it was let go
  await page.evaluate(() => window.__press(0, true));
  await pad.locator('input[name="gamepad"]').check();
  await waitFor(async () => (await pad.getAttribute("data-gamepad")) === "unarmed", "waits for the buttons at rest");
  const switchedOn = Date.now() / 1000;
  await waitFor(() => toolLog.ticks.some((x) => x > switchedOn + 0.3), "the tool's log a while after", 30000, 20);
  assert.equal(lastCall("close", switchedOn - 1), null, "close() from a button pressed before arming");
  await page.evaluate(() => window.__press(0, false));
  await waitFor(async () => (await pad.getAttribute("data-gamepad")) === "armed", "armed at rest");
  assert.match(await pad.locator(".gamepad-status").textContent(), /^Test pad: ready$/);

  // A held: close() and the fingers move; let go: halt()
  const before = Date.now() / 1000;
  await page.evaluate(() => window.__press(0, true));
  await waitFor(() => lastCall("close", before - 0.05), "close() from the gamepad", 20000, 10);
  await waitFor(async () => (await p.getAttribute("data-hold")) === "close", "the panel holds close");
  assert.match(await pad.locator(".gamepad-status").textContent(), /close \(A\)/);
  await waitFor(() => toolLog.moves.some((m) => m.tool > before), "the fingers moving", 20000, 10);
  const released = Date.now() / 1000;
  await page.evaluate(() => window.__press(0, false));
  await haltedAfter(released, "A let go");
  assert.equal(await p.getAttribute("data-hold-stop"), "gamepad released");

  // B held (open), then the gamepad lost: halt()
  const again = Date.now() / 1000;
  await page.evaluate(() => window.__press(1, true));
  await waitFor(() => lastCall("open", again - 0.05), "open() from the gamepad", 20000, 10);
  await waitFor(() => toolLog.moves.some((m) => m.tool > again), "the fingers moving", 20000, 10);
  const lost = Date.now() / 1000;
  await page.evaluate(() => { window.__pads.length = 0; });
  await haltedAfter(lost, "gamepad lost");
  assert.equal(await p.getAttribute("data-hold-stop"), "gamepad lost");
  await waitFor(async () => (await pad.getAttribute("data-gamepad")) === "none", "no gamepad shown");
  await screenshot(p, "std-tool-gamepad.png", { docs: false });
  await page.context().close();
  assert.deepEqual(pageErrors, []);
});
