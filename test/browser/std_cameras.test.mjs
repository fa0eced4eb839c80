// Cameras beyond one behind rr-gateway, in headless Chromium (issue 54): test/browser/devices/
// multi_camera.py on the official library serves a MultiCamera of three cameras (left, centre, right:
// each frame in the camera's own colour, PNG previews) and an ImagePartCamera whose capture_frame yields
// the raw frame in parts. The gateway has logins: alice (operator) and bob (viewer). Checked: the grid of
// the rig's previews, each named and in its camera's colour (PNG: exact), the raw map stream the same;
// Trigger all and Capture all for the operator only; the part camera's preview after Start streaming and
// its captured parts put back into the frame it sent; a rig without its picture pipes falling back to the
// generic view; no page error. Screenshots to $RR_ARTIFACTS (docs/img with RR_DOCS_SCREENSHOTS=1).

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import fs from "node:fs";
import { settings, launchChromium, waitFor } from "./harness.mjs";
import { startDevice, screenshot } from "./std_support.mjs";
import { gatewayWithLogins, loggedInPage, panelOf } from "./std_sensor_support.mjs";

const s = settings();
let cams, trimmed, gateway, tmp, browser, operator;
const pageErrors = [];

/** The RGB of pixel (x, y) of a canvas locator. */
const pixel = (canvas, x, y) => canvas.evaluate((c, [x, y]) => Array.from(c.getContext("2d", { willReadFrequently: true }).getImageData(x, y, 1, 1).data.slice(0, 3)), [x, y]);

/** Waits until the picture of `item` is drawn and its centre has `rgb`; returns what was read. */
async function centreIs(item, rgb, what) {
  const canvas = item.locator("canvas.frame-canvas");
  let got = null;
  await waitFor(async () => Number(await canvas.getAttribute("data-frames")) > 0
    && JSON.stringify(got = await pixel(canvas, 32, 30)) === JSON.stringify(rgb), what, 60000).catch(() => {});
  assert.deepEqual(got, rgb, what);
}

before(async () => {
  assert.ok(s.gateway, "RR_GATEWAY must be set");
  cams = await startDevice("multi_camera.py", ["--max-lifetime", "240"]);
  trimmed = await startDevice("multi_camera.py", ["--without-member", "preview_stream_all,frame_stream_compressed_all,frame_stream_all", "--max-lifetime", "240"]);
  ({ gateway, tmp } = await gatewayWithLogins({ rig: cams.info.url, parts: cams.info.parts_url, trimmed: trimmed.info.url }));
  browser = await launchChromium();
  operator = await loggedInPage(browser, gateway.base, "alice", "rig", pageErrors);
  await panelOf(operator, "rig", "multicamera").waitFor({ timeout: 60000 });
});

after(async () => {
  if (operator) await screenshot(operator, "std-cameras-end.png", { docs: false }).catch(() => {});
  await browser?.close();
  await gateway?.child.stop();
  await cams?.child.stop();
  await trimmed?.child.stop();
  if (tmp) fs.rmSync(tmp, { recursive: true, force: true });
});

test("a MultiCamera: each camera's preview named and in its colour; the raw map stream too", async () => {
  const p = panelOf(operator, "rig", "multicamera");
  await waitFor(async () => (await p.getAttribute("data-cameras")) === "3", "camera_names read");
  await waitFor(async () => (await p.getAttribute("data-pictures")) === "3", "three pictures", 60000);
  const names = ["left", "centre", "right"];
  for (let k = 0; k < 3; k++) {
    const item = p.locator(`.multicamera-grid .image-item[data-key="${k}"]`);
    assert.equal(await item.locator(".image-key").textContent(), `[${k}] ${names[k]}`);
    await centreIs(item, cams.info.colors[k], `${names[k]}'s preview in its colour`);
  }
  await screenshot(p, "dashboard-multicamera.png");
  await p.locator("select.camera-stream").selectOption("frame_stream_all");
  await waitFor(async () => (await p.getAttribute("data-stream-open")) === "frame_stream_all", "frame_stream_all open", 30000);
  for (let k = 0; k < 3; k++) await centreIs(p.locator(`.multicamera-grid .image-item[data-key="${k}"]`), cams.info.colors[k], `${names[k]}'s raw frame`);
  assert.deepEqual(pageErrors, []);
});

test("Trigger all and Capture all: the operator's, the viewer has neither", async () => {
  const p = panelOf(operator, "rig", "multicamera");
  await waitFor(async () => (await p.getAttribute("data-access")) === "checked", "access read", 30000);
  const triggered = cams.child.jsonLine("triggered", 15000);
  await p.locator('button[data-action="trigger_all"]').click();
  assert.deepEqual(await triggered, { triggered: 1 });
  await p.locator('button[data-action="capture_frame_all"]').click();
  await waitFor(async () => (await p.getAttribute("data-captured")) === "3", "three captured pictures", 30000);
  for (let k = 0; k < 3; k++) await centreIs(p.locator(`.multicamera-capture .image-item[data-key="${k}"]`), cams.info.colors[k], `captured ${k}`);

  const viewer = await loggedInPage(browser, gateway.base, "bob", "rig", pageErrors);
  const vp = panelOf(viewer, "rig", "multicamera");
  await waitFor(async () => (await vp.getAttribute("data-access")) === "checked", "viewer's access read", 30000);
  await waitFor(async () => (await vp.getAttribute("data-pictures")) === "3", "the viewer sees the pictures", 30000);
  assert.equal(await vp.locator('button[data-action="trigger_all"]').count(), 0);
  assert.equal(await vp.locator('button[data-action="capture_frame_all"]').count(), 0);
  await viewer.context().close();
  assert.deepEqual(pageErrors, []);
});

test("an ImagePartCamera: the preview after Start streaming, capture_frame's parts put back into the frame", async () => {
  await operator.goto(`${gateway.base}/#/parts`);
  const p = panelOf(operator, "parts", "image-part-camera");
  await p.waitFor({ timeout: 60000 });
  await p.locator('button[data-action="start_streaming"]').click();
  await waitFor(async () => /streaming/.test((await p.locator(".camera-state").getAttribute("data-flags")) || ""), "streaming", 30000);
  await centreIs(p.locator(".camera-live"), cams.info.colors[3], "the part camera's preview");
  const captured = cams.child.jsonLine("captured_parts", 15000);
  await p.locator('button[data-action="capture_frame"]').click();
  const { captured_parts: n } = await captured;
  const view = p.locator('.camera-capture .frame-view[data-capture="capture_frame"]');
  await view.waitFor({ timeout: 60000 });
  assert.equal(await view.getAttribute("data-parts"), String(n));
  await centreIs(p.locator(".camera-capture"), cams.info.colors[3], "the captured frame");
  assert.equal(await p.locator(".camera-error").isHidden(), true);
  await screenshot(p, "dashboard-image-part-camera.png");
  await p.locator('button[data-action="stop_streaming"]').click();
  assert.deepEqual(pageErrors, []);
});

test("a MultiCamera without its picture pipes: one line and the generic view", async () => {
  await operator.goto(`${gateway.base}/#/trimmed`);
  const p = panelOf(operator, "trimmed", "multicamera");
  await p.waitFor({ timeout: 60000 });
  assert.equal(await p.getAttribute("data-fallback"), "true");
  assert.match(await p.locator(".multicamera-fallback").textContent(), /no camera picture pipe/);
  await operator.locator('.device-view[data-device="trimmed"] section.member[data-member="capture_frame_all"]').waitFor({ timeout: 60000 });
  assert.deepEqual(pageErrors, []);
});
