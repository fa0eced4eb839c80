// Standard sensors behind rr-gateway, in headless Chromium (issue 54): test/browser/devices/sensors.py on
// the official library serves a WrenchSensor (a wrench following a pattern, held at known values on
// command), a two-value Sensor (temperature and humidity), an ImuSensor (spinning, held at a yaw on
// command) and a GpsSensor (walking a circle); the same script with --old-layout serves a
// WrenchSensor from an older, trimmed definition. The gateway has logins: alice (operator) and bob
// (viewer). Checked: the sensor panel shows each axis with its unit equal to what the device sent, the
// sensor_info rows, a live plot that grows, the value following the device; the IMU's orientation as
// roll, pitch, yaw and a gizmo whose pixels turn with it; the GPS fix, accuracy and a track that grows; the parameter control
// works for the operator and is absent for the viewer (whose calls the gateway refuses); the older
// layout falls back to the generic view; no page error anywhere. Screenshots to $RR_ARTIFACTS (docs/img
// with RR_DOCS_SCREENSHOTS=1).

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import fs from "node:fs";
import { settings, launchChromium, waitFor } from "./harness.mjs";
import { startDevice, screenshot } from "./std_support.mjs";
import { gatewayWithLogins, loggedInPage, command, panelOf } from "./std_sensor_support.mjs";

const s = settings();
let sensors, old, gateway, tmp, cookie, browser, operator, viewer;
const pageErrors = [];

const panel = (page, device = "wrench") => panelOf(page, device, "sensor");
const cell = (page, axis, part, device = "wrench") => panel(page, device).locator(`tr[data-axis="${axis}"] .sensor-${part}`);

before(async () => {
  assert.ok(s.gateway, "RR_GATEWAY must be set");
  sensors = await startDevice("sensors.py", ["--max-lifetime", "240"], { stdin: "pipe" });
  old = await startDevice("sensors.py", ["--old-layout", "--max-lifetime", "240"], { stdin: "pipe" });
  ({ gateway, tmp, cookie } = await gatewayWithLogins({
    wrench: sensors.info.url, climate: sensors.info.climate_url, imu: sensors.info.imu_url, gps: sensors.info.gps_url, wrench_old: old.info.url,
  }));
  browser = await launchChromium();
  operator = await loggedInPage(browser, gateway.base, "alice", "wrench", pageErrors);
  await panel(operator).waitFor({ timeout: 60000 });
});

after(async () => {
  if (operator) await screenshot(operator, "std-sensors-end.png", { docs: false }).catch(() => {});
  await browser?.close();
  await gateway?.child.stop();
  await sensors?.child.stop();
  await old?.child.stop();
  if (tmp) fs.rmSync(tmp, { recursive: true, force: true });
});

test("wrench: force and torque with units equal to what the device sent; sensor_info; live plot", async () => {
  const p = panel(operator);
  assert.equal(await p.getAttribute("data-source"), "wrench_sensor_value");
  assert.equal(await p.locator("h3").textContent(), "Force/torque sensor");
  await waitFor(async () => (await p.getAttribute("data-info")) === "read", "sensor_info read");
  assert.equal(await p.locator('dd[data-row="type"]').textContent(), "forcetorque");
  assert.equal(await p.locator('dd[data-row="update rate"]').textContent(), "50 Hz");
  assert.equal(await p.locator('dd[data-row="units"]').textContent(), sensors.info.units.join(", "));

  const held = { torque: [0.25, -0.5, 0.125], force: [12.5, -3.25, -49.05] };
  await command(sensors, { hold: held }, "held");
  const want = [...["x", "y", "z"].map((k, i) => [`force.${k}`, held.force[i], "N"]), ...["x", "y", "z"].map((k, i) => [`torque.${k}`, held.torque[i], "N·m"])];
  await waitFor(async () => {
    for (const [axis, v] of want) if (Number(await cell(operator, axis, "value").textContent()) !== v) return false;
    return true;
  }, "the held wrench shown", 15000);
  for (const [axis, , unit] of want) assert.equal(await cell(operator, axis, "unit").textContent(), unit, axis);
  assert.deepEqual(await p.locator("tr[data-axis]").evaluateAll((rows) => rows.map((r) => r.dataset.axis)),
    ["force.x", "force.y", "force.z", "torque.x", "torque.y", "torque.z"]);
  // the plot: one series per axis, with its unit, the newest equal to the held value
  const readout = p.locator(".plot-readout .readout-item");
  await waitFor(async () => (await readout.count()) === 6, "six plot series");
  assert.equal(await p.locator('.readout-item[data-series="force.z (N)"]').getAttribute("data-value"), "-49.05");
  const before = Number(await p.getAttribute("data-samples"));
  await waitFor(async () => Number(await p.getAttribute("data-samples")) >= before + 20, "20 more samples plotted", 15000);
  assert.match(await p.locator(".sensor-rate").textContent(), /^[\d.]+ samples\/s$/);
  await screenshot(p, "dashboard-sensor-wrench.png");

  // the pattern again: the shown value follows the device
  await command(sensors, { resume: true }, "resumed");
  await waitFor(async () => Number(await cell(operator, "force.x", "value").textContent()) !== 12.5, "force.x follows the pattern again", 15000);
  const fz = Number(await cell(operator, "force.z", "value").textContent());
  assert.ok(fz >= -54.05 && fz <= -44.05, `force.z in the pattern's range: ${fz}`);
  // the wire's own card below still works beside the panel (one wire connection shared)
  assert.deepEqual(pageErrors, []);
});

test("parameters: the operator gets and sets filter_cutoff; the viewer has no control and the gateway refuses its call", async () => {
  const p = panel(operator);
  await waitFor(async () => (await p.getAttribute("data-access")) === "checked", "access read");
  const params = p.locator('[data-panel-part="params"]');
  assert.equal(await params.locator("input.param-name").inputValue(), "filter_cutoff");
  await params.locator('button[data-action="getf_param"]').click();
  await waitFor(async () => (await params.locator(".param-result").textContent()) === "100", "filter_cutoff read");
  const set = sensors.child.jsonLine("param_set", 15000);
  await params.locator("input.param-value").fill("25");
  await params.locator('button[data-action="setf_param"]').click();
  assert.deepEqual(await set, { param_set: "filter_cutoff", value: 25 });
  await params.locator('button[data-action="getf_param"]').click();
  await waitFor(async () => (await params.locator(".param-result").textContent()) === "25", "filter_cutoff read back");

  viewer = await loggedInPage(browser, gateway.base, "bob", "wrench", pageErrors);
  const vp = panel(viewer);
  await waitFor(async () => (await vp.getAttribute("data-access")) === "checked", "viewer's access read", 30000);
  // the viewer sees the values, no control
  await waitFor(async () => (await vp.locator("tr[data-axis]").count()) === 6, "viewer sees six axes", 15000);
  assert.equal(await vp.locator('[data-panel-part="params"]').count(), 0);
  // and the gateway refuses the call the control would make, with bob's login (the page's cookie)
  const refused = await viewer.evaluate(async () => {
    const r = await fetch("api/devices/wrench/functions/setf_param", { method: "POST", headers: { "Content-Type": "application/json" },
      body: JSON.stringify({ args: ["filter_cutoff", { type: "double[]", value: [5] }] }) });
    return { status: r.status, body: await r.json() };
  });
  assert.equal(refused.status, 403, JSON.stringify(refused));
  assert.match(refused.body.error.name, /PermissionDenied/);
  assert.deepEqual(pageErrors, []);
});

test("a two-value Sensor: each value with its unit from sensor_info", async () => {
  await operator.goto(`${gateway.base}/#/climate`);
  const p = panel(operator, "climate");
  await p.waitFor({ timeout: 60000 });
  assert.equal(await p.getAttribute("data-source"), "sensor_value");
  await waitFor(async () => (await p.locator("tr[data-axis]").count()) === 2, "two values");
  await waitFor(async () => (await cell(operator, "[0]", "unit", "climate").textContent()) === "°C", "units from sensor_info");
  assert.equal(await cell(operator, "[1]", "unit", "climate").textContent(), "%");
  const t = Number(await cell(operator, "[0]", "value", "climate").textContent());
  const rh = Number(await cell(operator, "[1]", "value", "climate").textContent());
  assert.ok(t >= 21 && t <= 22, `temperature ${t}`);
  assert.ok(rh >= 38 && rh <= 42, `humidity ${rh}`);
  assert.equal(await p.locator('dd[data-row="type"]').textContent(), "temperature");
  await screenshot(p, "dashboard-sensor-climate.png");
  assert.deepEqual(pageErrors, []);
});

test("an older WrenchSensor definition (no wrench_sensor_value, no sensor_info): its sensor_value unnamed, the generic view, no page error", async () => {
  await operator.goto(`${gateway.base}/#/wrench_old`);
  const p = panel(operator, "wrench_old");
  await p.waitFor({ timeout: 60000 });
  // the panel takes the next standard wire the definition has: six numbers, no names or units to give them
  assert.equal(await p.getAttribute("data-source"), "sensor_value");
  await waitFor(async () => (await p.locator("tr[data-axis]").count()) === 6, "six values");
  assert.deepEqual(await p.locator("tr[data-axis] .sensor-unit").allTextContents(), ["", "", "", "", "", ""]);
  assert.equal(await p.locator(".sensor-info dd").count(), 0);
  await command(old, { hold: { torque: [1, 2, 3], force: [4, 5, 6] } }, "held");
  await waitFor(async () => (await p.locator("tr[data-axis] .sensor-value").allTextContents()).join(" ") === "1 2 3 4 5 6", "the held values, torque first as sensor_value orders them", 15000);
  // the generic member view below shows every member, the wire's card included
  const card = operator.locator('.device-view[data-device="wrench_old"] .member[data-member="sensor_value"]').first();
  await waitFor(async () => /1, 2, 3, 4, 5, 6/.test(await card.locator(".stream output.value").textContent().catch(() => "")), "sensor_value in its card", 20000);
  assert.ok(await operator.locator('.device-view[data-device="wrench_old"] .member[data-member="device_name"]').count() > 0, "the older definition's own member shown");
  assert.deepEqual(pageErrors, []);
});

/** Keeps a copy of a canvas's pixels in the page; resolves how many pixels differ from it later. */
const keepPixels = (canvas) => canvas.evaluate((c) => { c.keptPixels = c.getContext("2d", { willReadFrequently: true }).getImageData(0, 0, c.width, c.height).data; });
const changedPixels = (canvas) => canvas.evaluate((c) => {
  const now = c.getContext("2d", { willReadFrequently: true }).getImageData(0, 0, c.width, c.height).data;
  let k = 0;
  for (let i = 0; i < now.length; i += 4) if (now[i] !== c.keptPixels[i] || now[i + 1] !== c.keptPixels[i + 1] || now[i + 2] !== c.keptPixels[i + 2]) k++;
  return k;
});

test("IMU: orientation as roll, pitch, yaw and a gizmo that turns with it; rates and accelerations with units", async () => {
  await operator.goto(`${gateway.base}/#/imu`);
  const p = panelOf(operator, "imu", "imu");
  await p.waitFor({ timeout: 60000 });
  const row = (k) => p.locator(`dd[data-row="${k}"]`).textContent();
  await command(sensors, { imu_hold: 90 }, "imu_held");
  await waitFor(async () => (await row("orientation")) === "rpy (0, 0, 90)°", "yaw 90° shown", 15000);
  assert.equal(await row("angular velocity"), "(0, 0, 0) rad/s");
  assert.equal(await row("linear acceleration"), "(0, 0, 9.81) m/s²");
  const canvas = p.locator("canvas.imu-gizmo");
  // held: the gizmo stays as it is drawn
  await keepPixels(canvas);
  const n = Number(await p.getAttribute("data-samples"));
  await waitFor(async () => Number(await p.getAttribute("data-samples")) >= n + 5, "five more states drawn");
  assert.equal(await changedPixels(canvas), 0, "a still IMU, a still gizmo");
  await screenshot(p, "dashboard-imu.png");
  // another yaw: the text and the pixels follow
  await command(sensors, { imu_hold: -45 }, "imu_held");
  await waitFor(async () => (await row("orientation")) === "rpy (0, 0, -45)°", "yaw -45° shown", 15000);
  assert.ok(await changedPixels(canvas) > 50, "the gizmo turned");
  // the sensor panel beside it (ImuSensor implements Sensor): its sensor_info
  const sensor = panelOf(operator, "imu", "sensor");
  await waitFor(async () => (await sensor.locator('dd[data-row="type"]').textContent().catch(() => "")) === "inertial", "the sensor panel's type");
  assert.deepEqual(pageErrors, []);
});

test("GPS: position, fix, satellites and accuracy as sent; the track grows", async () => {
  await operator.goto(`${gateway.base}/#/gps`);
  const p = panelOf(operator, "gps", "gps");
  await p.waitFor({ timeout: 60000 });
  const row = (k) => p.locator(`dd[data-row="${k}"]`).textContent();
  await waitFor(async () => (await row("fix")) === "dgps_fix", "the fix by name", 15000);
  assert.equal(await row("altitude"), "120.5 m");
  assert.equal(await row("satellites"), "9 used of 14 visible");
  assert.equal(await row("horizontal error"), "0.8 m");
  assert.equal(await row("error"), "1.5 m");
  assert.equal(await row("speed"), "1 m/s");
  const [lat0, lon0] = sensors.info.gps_centre;
  // both rows from one snapshot: the cart moves, and two reads may straddle a redraw
  const [latText, lonText] = await p.evaluate((el) => ["latitude", "longitude"].map((k) => el.querySelector(`dd[data-row="${k}"]`).textContent));
  const lat = Number(latText.replace("°", "")), lon = Number(lonText.replace("°", ""));
  // on the circle of 20 m around the centre (1e-7° is about 1 cm)
  const north = (lat - lat0) * Math.PI / 180 * 6371008.8, east = (lon - lon0) * Math.PI / 180 * 6371008.8 * Math.cos(lat0 * Math.PI / 180);
  assert.ok(Math.abs(Math.hypot(north, east) - 20) < 0.05, `${Math.hypot(north, east)} m from the centre`);
  const canvas = p.locator("canvas.gps-track");
  await keepPixels(canvas);
  await waitFor(async () => (await changedPixels(canvas)) > 5, "the track grew", 20000);
  await screenshot(p, "dashboard-gps.png");
  assert.deepEqual(pageErrors, []);
});
