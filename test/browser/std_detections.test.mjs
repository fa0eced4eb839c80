// Fiducial and object recognition sensors behind rr-gateway, in headless Chromium (issue 54):
// test/browser/devices/detections.py on the official library sees two ArUco markers and two objects
// (held still). The gateway has logins: alice (operator) and bob (viewer). Checked: the sensor's info and
// every detection as a row of what was seen, its class, its pose in the camera's frame and the
// confidence, equal to what the device sent; Capture and the parameters for the operator only; a sensor
// without its pipe falling back to the generic view; no page error. Screenshots to $RR_ARTIFACTS
// (docs/img with RR_DOCS_SCREENSHOTS=1).

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import fs from "node:fs";
import { settings, launchChromium, waitFor } from "./harness.mjs";
import { startDevice, screenshot } from "./std_support.mjs";
import { gatewayWithLogins, loggedInPage, panelOf } from "./std_sensor_support.mjs";

const s = settings();
let det, trimmed, gateway, tmp, browser, operator;
const pageErrors = [];
const panel = (page, device) => panelOf(page, device, "detections");
const rows = (p) => p.locator("table.detections-table tbody tr").evaluateAll((trs) => trs.map((tr) => Array.from(tr.cells, (c) => c.textContent)));

before(async () => {
  assert.ok(s.gateway, "RR_GATEWAY must be set");
  det = await startDevice("detections.py", ["--hold", "--max-lifetime", "240"]);
  trimmed = await startDevice("detections.py", ["--hold", "--without-member", "fiducials_sensor_data", "--max-lifetime", "240"]);
  ({ gateway, tmp } = await gatewayWithLogins({ tags: det.info.url, objects: det.info.objects_url, trimmed: trimmed.info.url }));
  browser = await launchChromium();
  operator = await loggedInPage(browser, gateway.base, "alice", "tags", pageErrors);
  await panel(operator, "tags").waitFor({ timeout: 60000 });
});

after(async () => {
  if (operator) await screenshot(operator, "std-detections-end.png", { docs: false }).catch(() => {});
  await browser?.close();
  await gateway?.child.stop();
  await det?.child.stop();
  await trimmed?.child.stop();
  if (tmp) fs.rmSync(tmp, { recursive: true, force: true });
});

test("fiducials: the sensor's info and each marker with its class, pose and confidence", async () => {
  const p = panel(operator, "tags");
  await waitFor(async () => (await p.getAttribute("data-info")) === "read", "fiducial_sensor_info read", 60000);
  const row = (k) => p.locator(`dd[data-row="${k}"]`).textContent();
  assert.equal(await row("range"), "2 × 1.5 × 3 m at (0, 0, 1.5)");
  assert.equal(await row("resolution"), "0.002 m");
  assert.equal(await row("markers"), "aruco_4x4_50 0-49");
  await waitFor(async () => Number(await p.getAttribute("data-updates")) >= 2, "detections shown", 60000);
  assert.deepEqual(await rows(p), [
    ["aruco_4x4:7", "aruco_4x4_50", "position (0.4, 0.1, 1.2) m, rpy (0, 0, 90)°", "camera_link", "98 %"],
    ["aruco_4x4:12", "aruco_4x4_50", "position (-0.25, 0, 0.8) m, rpy (0, 0, 0)°", "camera_link", "90 %"],
  ]);
  assert.match(await p.locator(".detections-status").textContent(), /^2 detections \(fiducials_sensor_data\); seqno \d+$/);
  await screenshot(p, "dashboard-fiducials.png");
  assert.deepEqual(pageErrors, []);
});

test("object recognition: each object with its class, pose and confidence", async () => {
  await operator.goto(`${gateway.base}/#/objects`);
  const p = panel(operator, "objects");
  await waitFor(async () => Number(await p.getAttribute("data-updates")) >= 2, "objects shown", 60000);
  // the templates row comes from the sensor's info property, read apart from the pipe: wait for that read
  await waitFor(async () => (await p.getAttribute("data-info")) === "read", "object_recognition_sensor_info read", 60000);
  assert.equal(await p.locator('dd[data-row="templates"]').textContent(), "mug, gearbox");
  assert.deepEqual(await rows(p), [
    ["mug", "cup", "position (0.3, -0.1, 0.75) m, rpy (0, 0, 0)°", "camera_link", "87 %"],
    ["gearbox", "part", "position (0, 0.2, 0.9) m, rpy (0, 0, 0)°", "camera_link", "61 %"],
  ]);
  await screenshot(p, "dashboard-object-recognition.png");
  assert.deepEqual(pageErrors, []);
});

test("Capture and parameters: the operator's, the viewer has none", async () => {
  const p = panel(operator, "objects");
  await waitFor(async () => (await p.getAttribute("data-access")) === "checked", "access read", 60000);
  await p.locator('button[data-action="capture_recognized_objects"]').click();
  await waitFor(async () => (await p.getAttribute("data-shown")) === "capture_recognized_objects", "the captured detections shown", 60000);
  assert.equal((await rows(p)).length, 2);
  await p.locator('button[data-action="live"]').click();
  await waitFor(async () => (await p.getAttribute("data-shown")) === "object_recognition_sensor_data", "live again", 60000);
  const params = p.locator('[data-panel-part="params"]');
  assert.equal(await params.locator("input.param-name").inputValue(), "threshold");
  const set = det.child.jsonLine("param_set", 15000);
  await params.locator("input.param-value").fill("0.75");
  await params.locator('button[data-action="setf_param"]').click();
  assert.deepEqual(await set, { param_set: "threshold", value: 0.75 });

  const viewer = await loggedInPage(browser, gateway.base, "bob", "objects", pageErrors);
  const vp = panel(viewer, "objects");
  await waitFor(async () => (await vp.getAttribute("data-access")) === "checked", "viewer's access read", 60000);
  await waitFor(async () => Number(await vp.getAttribute("data-updates")) >= 1, "the viewer sees detections", 60000);
  assert.equal(await vp.locator('button[data-action="capture_recognized_objects"]').count(), 0);
  assert.equal(await vp.locator('[data-panel-part="params"]').count(), 0);
  await viewer.context().close();
  assert.deepEqual(pageErrors, []);
});

test("a fiducial sensor without its pipe: one line and the generic view", async () => {
  await operator.goto(`${gateway.base}/#/trimmed`);
  const p = panel(operator, "trimmed");
  await p.waitFor({ timeout: 60000 });
  assert.equal(await p.getAttribute("data-fallback"), "true");
  assert.match(await p.locator(".detections-fallback").textContent(), /no fiducials_sensor_data pipe of the standard type/);
  await operator.locator('.device-view[data-device="trimmed"] section.member[data-member="capture_fiducials"]').waitFor({ timeout: 60000 });
  assert.deepEqual(pageErrors, []);
});
