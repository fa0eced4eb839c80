// The light panel (issue 54) on three lights served by the official library (test/browser/devices/
// sim_lights.py: a Light, a DimmableLight and a ColorTunableLight) behind rr-gateway with logins
// (operator alice, viewer bob): the values shown equal what the device holds (brightness in %, the colour
// as hex and fractions, maximum lumens); turning on, the brightness slider and the colour picker reach
// the device with the values set (its write log) and the swatch's colour changes with them; a Light
// shows only on/off; a viewer sees no control; lights without on_off fall back to the generic view with
// no page error. Screenshot to $RR_ARTIFACTS (docs/img with RR_DOCS_SCREENSHOTS=1).

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";
import { settings, writeOperatorViewerConfig, startGateway, launchChromium, waitFor } from "./harness.mjs";
import { startDevice, screenshot } from "./std_support.mjs";

const s = settings();
let tmp, lights, oldLights, gateway, browser, operator;
const writes = [];
const pageErrors = [];

before(async () => {
  assert.ok(s.gateway, "RR_GATEWAY must be set");
  tmp = fs.mkdtempSync(path.join(os.tmpdir(), "rr-web-lights-"));
  lights = await startDevice("sim_lights.py", ["--max-lifetime", "200"]);
  lights.child.lines.on("line", (line) => {
    try {
      const v = JSON.parse(line);
      if (typeof v.light === "string") writes.push(v);
    } catch { /* not a log line */ }
  });
  oldLights = await startDevice("sim_lights.py", ["--without-member", "on_off", "--max-lifetime", "200"]);
  const config = writeOperatorViewerConfig(tmp, [
    "devices:",
    ...["light", "dimmer", "lamp"].flatMap((n) => [`  - name: ${n}`, `    url: ${lights.info.urls[n]}`]),
    "  - name: oldlamp",
    `    url: ${oldLights.info.urls.lamp}`,
  ]);
  gateway = await startGateway(s, {}, 0, ["--config", config, "--no-demo", "--no-discovery"]);
  browser = await launchChromium();
  operator = await loggedIn("alice", "alice-pw");
});

after(async () => {
  await browser?.close();
  await gateway?.child.stop();
  await lights?.child.stop();
  await oldLights?.child.stop();
  if (tmp) fs.rmSync(tmp, { recursive: true, force: true });
});

const panel = (page, device) => page.locator(`.device-view[data-device="${device}"] [data-panel="light"]`);
const row = (page, device, key) => panel(page, device).locator(`dd[data-row="${key}"]`);
const swatchColor = (page, device) => panel(page, device).locator(".light-swatch").evaluate((e) => getComputedStyle(e).backgroundColor);
const lastWrite = (light, member) => writes.filter((w) => w.light === light && w.member === member).at(-1) ?? null;

async function loggedIn(user, password) {
  const context = await browser.newContext({ viewport: { width: 1280, height: 900 } });
  const page = await context.newPage();
  page.on("pageerror", (e) => pageErrors.push(`${user}: ${e}`));
  await page.goto(`${gateway.base}/#/lamp`);
  await page.waitForURL(/\/login\.html/, { timeout: 20000 });
  await page.fill("#login-username", user);
  await page.fill("#login-password", password);
  await page.click("#login-submit");
  await page.waitForURL((u) => !/login\.html/.test(String(u)), { timeout: 20000 });
  return page;
}

async function open(page, device) {
  await page.goto(`${gateway.base}/#/${device}`);
  await panel(page, device).waitFor({ timeout: 60000 });
  await waitFor(async () => (await panel(page, device).getAttribute("data-ready")) === "true", `${device} panel ready`, 40000);
  await waitFor(async () => Number((await panel(page, device).getAttribute("data-reads")) ?? 0) > 0, `${device} read`, 20000);
}

test("colour-tunable lamp: values as the device holds them; on, brightness and colour reach it", async () => {
  await open(operator, "lamp");
  const p = panel(operator, "lamp");
  assert.equal(await row(operator, "lamp", "on_off").textContent(), "off");
  assert.equal(await row(operator, "lamp", "intensity").textContent(), "50%");
  assert.equal(await row(operator, "lamp", "color").textContent(), "#ffbf4d (r 1.000, g 0.750, b 0.300, a 1.000)");
  await waitFor(async () => (await row(operator, "lamp", "max_lumens").count()) === 1, "max lumens");
  assert.equal(await row(operator, "lamp", "max_lumens").textContent(), "2500 lm");
  assert.equal(await swatchColor(operator, "lamp"), "rgb(0, 0, 0)");  // off: dark

  await p.getByRole("button", { name: "Turn on" }).click();
  await waitFor(() => lastWrite("lamp", "on_off")?.value === true, "on_off true reached the lamp");
  await waitFor(async () => (await row(operator, "lamp", "on_off").textContent()) === "on", "shown on");
  // warm white at 50 %: (255, 191, 77) × 0.5
  await waitFor(async () => (await swatchColor(operator, "lamp")) === "rgb(128, 96, 38)", "the swatch lit");

  await p.locator('input[name="light-intensity"]').fill("0.8");
  await p.locator('input[name="light-intensity"]').dispatchEvent("change");
  await waitFor(() => lastWrite("lamp", "intensity")?.value === 0.8, "intensity 0.8 reached the lamp");
  await waitFor(async () => (await row(operator, "lamp", "intensity").textContent()) === "80%", "shown 80%");

  await p.locator('input[name="light-color"]').fill("#3366cc");
  await waitFor(() => lastWrite("lamp", "color") !== null && lastWrite("lamp", "color").value[2] === 0.8, "colour reached the lamp");
  const [r, g, b, a] = lastWrite("lamp", "color").value;
  assert.deepEqual([r, g, b, a].map((x) => Math.round(x * 255)), [0x33, 0x66, 0xcc, 255]);
  await waitFor(async () => (await row(operator, "lamp", "color").textContent()).startsWith("#3366cc (r 0.200, g 0.400, b 0.800, a 1.000)"), "colour shown");
  // (0x33, 0x66, 0xcc) × 0.8
  await waitFor(async () => (await swatchColor(operator, "lamp")) === "rgb(41, 82, 163)", "the swatch's colour changed");
  await screenshot(p, "dashboard-light.png");
  assert.deepEqual(pageErrors, []);
});

test("a plain Light shows on/off only; a dimmer adds brightness but no colour", async () => {
  await open(operator, "light");
  assert.equal(await panel(operator, "light").locator('input[name="light-intensity"], input[name="light-color"]').count(), 0);
  assert.equal(await row(operator, "light", "intensity").count(), 0);
  await panel(operator, "light").getByRole("button", { name: "Turn on" }).click();
  await waitFor(() => lastWrite("light", "on_off")?.value === true, "on_off reached the light");
  await waitFor(async () => (await swatchColor(operator, "light")) === "rgb(255, 255, 255)", "white when on");
  await open(operator, "dimmer");
  assert.equal(await panel(operator, "dimmer").locator('input[name="light-intensity"]').count(), 1);
  assert.equal(await panel(operator, "dimmer").locator('input[name="light-color"]').count(), 0);
  // light_info is read apart from the properties open() waited for: wait for its row, as for the lamp
  await waitFor(async () => (await row(operator, "dimmer", "max_lumens").count()) === 1, "dimmer max lumens", 30000);
  assert.equal(await row(operator, "dimmer", "max_lumens").textContent(), "1200 lm");
  assert.deepEqual(pageErrors, []);
});

test("a viewer sees the state, no control", async () => {
  const page = await loggedIn("bob", "bob-pw");
  await open(page, "lamp");
  assert.equal(await panel(page, "lamp").getAttribute("data-access"), "checked");
  await waitFor(async () => (await row(page, "lamp", "on_off").textContent()) === "on", "viewer sees on");
  assert.equal(await panel(page, "lamp").locator("button, input").count(), 0);
  await page.context().close();
  assert.deepEqual(pageErrors, []);
});

test("lights without on_off fall back to the generic view, with no page error", async () => {
  await operator.goto(`${gateway.base}/#/oldlamp`);
  const p = panel(operator, "oldlamp");
  await p.waitFor({ timeout: 60000 });
  assert.equal(await p.getAttribute("data-fallback"), "true");
  await operator.locator('.device-view[data-device="oldlamp"] .member[data-member="intensity"]').first().waitFor({ timeout: 60000 });
  assert.deepEqual(pageErrors, []);
});
