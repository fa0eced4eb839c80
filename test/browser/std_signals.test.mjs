// The signal panel (issue 54) on a work cell's I/O served by the official library
// (test/browser/devices/signals.py: a SignalDevice with input and output groups, a SignalGroup and a
// lone Signal) behind rr-gateway with logins (alice: operator, bob: viewer): every signal with its type,
// value (as the device sends it), units and access level, grouped as the device groups them; the
// operator's switch and number input reach the device (its command log) and the value shown follows;
// a value above the signal's maximum is refused by the page with nothing sent; signals that are not
// writable (readonly, restricted) get no control; the viewer gets none at all; a SignalDevice without
// signal_groups falls back to the generic view. No page error. Screenshot to $RR_ARTIFACTS (docs/img
// with RR_DOCS_SCREENSHOTS=1).

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import fs from "node:fs";
import { launchChromium, waitFor } from "./harness.mjs";
import { startDevice, screenshot } from "./std_support.mjs";
import { gatewayWithLogins, loggedInPage, panelOf } from "./std_sensor_support.mjs";

let signals, oldSignals, gw, browser, operator;
const pageErrors = [];
const log = [];

before(async () => {
  signals = await startDevice("signals.py", ["--max-lifetime", "250"]);
  signals.child.lines.on("line", (line) => {
    try { const v = JSON.parse(line); if (typeof v.signal === "string") log.push(v); } catch { /* not a log line */ }
  });
  oldSignals = await startDevice("signals.py", ["--without-member", "signal_groups", "--max-lifetime", "250"]);
  gw = await gatewayWithLogins({ io: signals.info.urls.io, lamps: signals.info.urls.lamps, gauge: signals.info.urls.gauge, oldio: oldSignals.info.urls.io });
  browser = await launchChromium();
  operator = await loggedInPage(browser, gw.gateway.base, "alice", "io", pageErrors);
});

after(async () => {
  await browser?.close();
  await gw?.gateway.child.stop();
  await signals?.child.stop();
  await oldSignals?.child.stop();
  if (gw?.tmp) fs.rmSync(gw.tmp, { recursive: true, force: true });
});

const row = (page, device, name) => panelOf(page, device, "signal").locator(`tr[data-signal="${name}"]`);
const value = (page, device, name) => row(page, device, name).locator(".signal-value");
const cells = async (page, device, name) => (await row(page, device, name).locator("td").allTextContents()).slice(0, 4);
async function cellsShown(page, device, name, expected) {
  await waitFor(async () => (await value(page, device, name).textContent()) !== "", `${name} value shown`, 30000);
  assert.deepEqual(await cells(page, device, name), expected);
}
const logged = (name) => log.filter((x) => x.signal === name);

async function open(page, device) {
  await page.goto(`${gw.gateway.base}/#/${device}`);
  const p = panelOf(page, device, "signal");
  await p.waitFor({ timeout: 60000 });
  await waitFor(async () => (await p.getAttribute("data-ready")) === "true", `${device} signal panel ready`, 40000);
  return p;
}

test("signal device: groups, values with units, types and access as the device sends them", async () => {
  const p = await open(operator, "io");
  assert.deepEqual(await p.locator(".signal-group h4").allTextContents(), ["inputs: Cell inputs", "outputs: Cell outputs"]);
  assert.equal(await p.getAttribute("data-signals"), "8");
  await waitFor(async () => (await value(operator, "io", "cell_temperature").textContent()) === "21.5 °C", "cell_temperature shown", 30000);
  // each signal has its own signal_value wire, so each value arrives on its own: wait for each one
  await cellsShown(operator, "io", "door_closed", ["door_closed", "digital", "on", "readonly"]);
  await cellsShown(operator, "io", "safety_relay", ["safety_relay", "digital", "on", "restricted"]);
  await cellsShown(operator, "io", "conveyor_speed", ["conveyor_speed", "analog", "0 m/s", "all"]);
  // live: the pressure moves, the part sensor goes on and off
  const pressure = async () => Number((await value(operator, "io", "air_pressure").textContent()).replace(" bar", ""));
  // air_pressure's value comes on its own wire too: wait for it before reading the first one
  await waitFor(async () => (await value(operator, "io", "air_pressure").textContent()) !== "", "air_pressure shown", 30000);
  const first = await pressure();
  assert.ok(first >= 5.8 && first <= 6.2, `air_pressure ${first} bar`);
  await waitFor(async () => (await pressure()) !== first, "air_pressure moving");
  const seen = new Set();
  await waitFor(async () => { seen.add(await value(operator, "io", "part_present").textContent()); return seen.has("on") && seen.has("off"); }, "part_present on and off", 20000, 50);
  // controls: only for writable signals
  for (const name of ["door_closed", "part_present", "air_pressure", "cell_temperature", "safety_relay"]) {
    assert.equal(await row(operator, "io", name).locator("input, button").count(), 0, `${name} has a control`);
  }
  assert.deepEqual(pageErrors, []);
});

test("signal device: the operator's switch and value reach the device; out of range is refused in the page", async () => {
  const p = await open(operator, "io");
  await waitFor(async () => (await value(operator, "io", "valve_a").textContent()) === "off", "valve_a off");
  await row(operator, "io", "valve_a").locator('input[type="checkbox"]').check();
  await waitFor(() => logged("valve_a").some((x) => x.command?.[0] === 1), "valve_a on reached the device");
  await waitFor(async () => (await value(operator, "io", "valve_a").textContent()) === "on", "valve_a shown on");

  const speed = row(operator, "io", "conveyor_speed");
  await speed.locator('input[type="number"]').fill("0.25");
  await speed.getByRole("button", { name: "Set" }).click();
  await waitFor(() => logged("conveyor_speed").some((x) => x.command?.[0] === 0.25), "0.25 m/s reached the device");
  await waitFor(async () => (await value(operator, "io", "conveyor_speed").textContent()) === "0.25 m/s", "0.25 m/s shown");
  await screenshot(p, "dashboard-signals.png");

  const before = logged("conveyor_speed").length;
  await speed.locator('input[type="number"]').fill("0.8");
  await speed.getByRole("button", { name: "Set" }).click();
  await waitFor(async () => (await p.locator(".signal-error").textContent()) === "conveyor_speed: 0.8 is above its maximum 0.5", "the page's refusal");
  assert.equal(logged("conveyor_speed").length, before, "a value above the maximum was sent");
  assert.equal(await value(operator, "io", "conveyor_speed").textContent(), "0.25 m/s");
  assert.deepEqual(pageErrors, []);
});

test("a SignalGroup and a lone Signal at the root", async () => {
  await open(operator, "lamps");
  await waitFor(async () => (await value(operator, "lamps", "lamp_red").textContent()) === "off", "lamp_red off");
  await row(operator, "lamps", "lamp_red").locator('input[type="checkbox"]').check();
  await waitFor(() => logged("lamp_red").some((x) => x.command?.[0] === 1), "lamp_red on reached the device");
  await waitFor(async () => (await value(operator, "lamps", "lamp_red").textContent()) === "on", "lamp_red shown on");

  await open(operator, "gauge");
  await waitFor(async () => (await value(operator, "gauge", "line_pressure").textContent()) === "4.25 bar", "line_pressure shown");
  assert.deepEqual(await cells(operator, "gauge", "line_pressure"), ["line_pressure", "analog", "4.25 bar", "readonly"]);
  assert.equal(await panelOf(operator, "gauge", "signal").locator("input, button").count(), 0);
  assert.deepEqual(pageErrors, []);
});

test("a viewer sees every value and no control; a device without signal_groups falls back", async () => {
  const page = await loggedInPage(browser, gw.gateway.base, "bob", "io", pageErrors);
  const p = await open(page, "io");
  assert.equal(await p.getAttribute("data-access"), "checked");
  await waitFor(async () => (await value(page, "io", "cell_temperature").textContent()) === "21.5 °C", "values shown to the viewer", 30000);
  assert.equal(await p.locator("input, button").count(), 0);

  await page.goto(`${gw.gateway.base}/#/oldio`);
  const old = panelOf(page, "oldio", "signal");
  await old.waitFor({ timeout: 60000 });
  assert.equal(await old.getAttribute("data-fallback"), "true");
  await page.locator('.device-view[data-device="oldio"] .member[data-member="signal_group_info"]').first().waitFor({ timeout: 60000 });
  await page.context().close();
  assert.deepEqual(pageErrors, []);
});
