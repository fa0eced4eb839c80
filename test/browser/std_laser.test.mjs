// Standard laser scanners behind rr-gateway, in headless Chromium (issue 54): test/browser/devices/
// laser_scanner.py on the official library scans a room (walls, a pillar, a person walking) at 10 Hz as
// a LaserScanner (whole scans) and a LaserScanPartScanner (each scan in three parts). The gateway has
// logins: alice (operator) and bob (viewer). Checked: the scanner's info and each scan's geometry as
// the device sent them; the wall straight ahead drawn where its range puts it, in its intensity's
// colour; the drawing changes as the person walks; the parts put back into the same whole scan; the
// parameter control for the operator only; no page error. Screenshots to $RR_ARTIFACTS (docs/img with
// RR_DOCS_SCREENSHOTS=1).

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import fs from "node:fs";
import { settings, launchChromium, waitFor } from "./harness.mjs";
import { startDevice, screenshot } from "./std_support.mjs";
import { gatewayWithLogins, loggedInPage, panelOf } from "./std_sensor_support.mjs";
import { jetTable } from "../../web/src/std/colormap.js";

const s = settings();
let scanner, gateway, tmp, browser, operator;
const pageErrors = [];
const panel = (page, device = "scanner") => panelOf(page, device, "laser-scanner");

before(async () => {
  assert.ok(s.gateway, "RR_GATEWAY must be set");
  scanner = await startDevice("laser_scanner.py", ["--max-lifetime", "240"], { stdin: "pipe" });
  ({ gateway, tmp } = await gatewayWithLogins({ scanner: scanner.info.url, parts: scanner.info.parts_url }));
  browser = await launchChromium();
  operator = await loggedInPage(browser, gateway.base, "alice", "scanner", pageErrors);
  await panel(operator).waitFor({ timeout: 60000 });
});

after(async () => {
  if (operator) await screenshot(operator, "std-laser-end.png", { docs: false }).catch(() => {});
  await browser?.close();
  await gateway?.child.stop();
  await scanner?.child.stop();
  if (tmp) fs.rmSync(tmp, { recursive: true, force: true });
});

test("the scanner's info and the scan as the device sent them; the wall ahead where its range puts it", async () => {
  const p = panel(operator);
  await waitFor(async () => (await p.getAttribute("data-info")) === "read", "scanner_info read");
  const row = (k) => p.locator(`dd[data-row="${k}"]`).textContent();
  assert.equal(await row("angle range"), "-135° to 135°");
  assert.equal(await row("resolution"), "0.5°");
  assert.equal(await row("range"), "0.05 to 10 m");
  assert.equal(await row("scan rate"), "10 Hz");
  await waitFor(async () => Number(await p.getAttribute("data-scans")) >= 3, "three scans drawn", 20000);
  assert.match(await p.locator(".scan-status").textContent(), /^541 ranges, -135° to 135° by 0\.5°, 0\.05 to 10 m; 541 returns; [\d.]+ scans\/s.*; seqno \d+$/);
  assert.equal(await p.getAttribute("data-points"), "541");

  // straight ahead (index 270) the wall at x = 4 m, intensity 100 of the scan's 50..200: jet at 1/3
  const canvas = p.locator("canvas.scan-canvas");
  const at = (x, y) => canvas.evaluate((c, [x, y]) => Array.from(c.getContext("2d", { willReadFrequently: true }).getImageData(x, y, 1, 1).data.slice(0, 3)), [x, y]);
  const size = await canvas.evaluate((c) => [c.width, c.height]);
  const cx = size[0] / 2, cy = size[1] / 2;
  const jet = jetTable(), k = Math.round(((100 - 50) / 150) * 255) * 3;
  const wantWall = [jet[k], jet[k + 1], jet[k + 2]];
  // the view zooms out when a farther return comes (a corner the walking person uncovers): the scale
  // read and the pixel read must belong to the same drawing, so both are read until they agree
  let scale, y, wall;
  await waitFor(async () => {
    scale = Number(await p.getAttribute("data-scale"));
    y = Math.round(cy - 4 * scale);
    wall = await at(cx, y);
    return scale === Number(await p.getAttribute("data-scale")) && wall.every((c, i) => c === wantWall[i]);
  }, "the wall ahead drawn 4 m up", 10000).catch(() => {});
  assert.deepEqual(wall, wantWall, `the wall ahead at (${cx}, ${y}), ${scale} px/m`);
  // nothing drawn halfway to it (free floor: background or a ring)
  const floor = await at(cx + 3, Math.round(cy - 2.5 * scale));
  assert.ok(floor.every((c) => c >= 200), `free floor: ${floor}`);
  await screenshot(p, "dashboard-laser-scanner.png");
  assert.deepEqual(pageErrors, []);
});

test("the drawing changes as the person walks (newest scan wins)", async () => {
  const p = panel(operator);
  const canvas = p.locator("canvas.scan-canvas");
  // the picture kept in the page, compared there (a 480 × 480 canvas is slow to copy out on every poll)
  await canvas.evaluate((c) => { c.firstPixels = c.getContext("2d", { willReadFrequently: true }).getImageData(0, 0, c.width, c.height).data; });
  const n = Number(await p.getAttribute("data-scans"));
  await waitFor(async () => Number(await p.getAttribute("data-scans")) >= n + 3, "three more scans drawn", 20000);
  let changed = 0;
  await waitFor(async () => {
    changed = await canvas.evaluate((c) => {
      const now = c.getContext("2d", { willReadFrequently: true }).getImageData(0, 0, c.width, c.height).data;
      let k = 0;
      for (let i = 0; i < now.length; i += 4) if (now[i] !== c.firstPixels[i] || now[i + 1] !== c.firstPixels[i + 1]) k++;
      return k;
    });
    return changed > 10;
  }, "pixels changed", 20000);
  assert.ok(changed > 10, `${changed} pixels changed`);
});

test("a LaserScanPartScanner: three parts put back into the whole scan", async () => {
  await operator.goto(`${gateway.base}/#/parts`);
  const p = panel(operator, "parts");
  await p.waitFor({ timeout: 60000 });
  await waitFor(async () => Number(await p.getAttribute("data-scans")) >= 3, "three whole scans drawn", 20000);
  assert.equal(await p.getAttribute("data-points"), "541");
  assert.match(await p.locator(".scan-status").textContent(), /^541 ranges, -135° to 135° by 0\.5°/);
  assert.doesNotMatch(await p.locator(".scan-status").textContent(), /incomplete/, "no scan begun and left unfinished");
  assert.deepEqual(pageErrors, []);
});

test("parameters: the operator's control works, the viewer has none", async () => {
  await operator.goto(`${gateway.base}/#/scanner`);
  const p = panel(operator);
  await waitFor(async () => (await p.getAttribute("data-access")) === "checked", "access read", 30000);
  const params = p.locator('[data-panel-part="params"]');
  assert.equal(await params.locator("input.param-name").inputValue(), "motor_speed");
  const set = scanner.child.jsonLine("param_set", 15000);
  await params.locator("input.param-value").fill("12.5");
  await params.locator('button[data-action="setf_param"]').click();
  assert.deepEqual(await set, { param_set: "motor_speed", value: 12.5 });
  await params.locator('button[data-action="getf_param"]').click();
  await waitFor(async () => (await params.locator(".param-result").textContent()) === "12.5", "motor_speed read back");

  const viewer = await loggedInPage(browser, gateway.base, "bob", "scanner", pageErrors);
  const vp = panel(viewer);
  await waitFor(async () => (await vp.getAttribute("data-access")) === "checked", "viewer's access read", 30000);
  await waitFor(async () => Number(await vp.getAttribute("data-scans")) >= 1, "the viewer sees scans", 20000);
  assert.equal(await vp.locator('[data-panel-part="params"]').count(), 0);
  assert.deepEqual(pageErrors, []);
});
