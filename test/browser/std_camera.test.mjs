// The official camera driver (PyPI robotraconteur-camera-driver) behind rr-gateway, in headless
// Chromium (issue 41): test/browser/devices/camera_synthetic.py runs the driver as shipped with a
// synthetic OpenCV capture whose frames the test recomputes from the frame number each one spells
// in its top row. The device opens with its device card (from its own info file) and the camera
// panel; Start streaming from the panel makes the picture appear on the preview stream (JPEG), the
// raw stream (bgr888, every pixel equal) and the compressed stream (JPEG); captures draw the same;
// Stop streaming stops the picture. Screenshots go to $RR_ARTIFACTS (docs/img with RR_DOCS_SCREENSHOTS=1).

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import path from "node:path";
import { settings, startGateway, launchChromium, apiDevices, waitFor } from "./harness.mjs";
import { DEVICES, startDevice, screenshot, compareWithPattern } from "./std_support.mjs";

const s = settings();
let camera, gateway, browser, page;
const pageErrors = [];

const view = () => page.locator('.device-view[data-device="camera"]');
const panel = () => view().locator('[data-panel="camera"]');
const live = () => panel().locator(".camera-live .frame-view").first();
const num = async (loc, name) => Number((await loc.getAttribute(name)) || 0);

/** Waits for `n` more frames drawn in `fig` and compares the newest with the frame it spells. */
async function framesMatch(fig, n, margin, what) {
  const start = await num(fig, "data-drawn");
  await waitFor(async () => (await num(fig, "data-drawn")) >= start + n, `${n} ${what} frames drawn`, 20000);
  // compare a frame that stays put: the picture only changes in an animation frame, so read it in one
  const r = await compareWithPattern(fig.locator("canvas"), camera.info, margin);
  assert.deepEqual([r.width, r.height], [camera.info.width, camera.info.height], `${what}: size`);
  return r;
}

before(async () => {
  assert.ok(s.gateway, "RR_GATEWAY must be set");
  camera = await startDevice("camera_synthetic.py",
    ["--camera-info", path.join(DEVICES, "synthetic_camera_info.yml"), "--width", "320", "--height", "240", "--fps", "15",
      "--max-lifetime", "240"]);
  gateway = await startGateway(s, { camera: camera.info.url }, 0, ["--no-demo", "--no-discovery"]);
  await waitFor(async () => (await apiDevices(gateway.base)).find((d) => d.name === "camera")?.state === "connected",
    "camera connected", 30000);
  browser = await launchChromium();
  page = await (await browser.newContext({ viewport: { width: 1366, height: 1000 } })).newPage();
  page.on("pageerror", (e) => pageErrors.push(e));
  await page.goto(`${gateway.base}/#/camera`);
  await panel().waitFor({ timeout: 60000 });
});

after(async () => {
  if (page) await screenshot(page, "std-camera-end.png", { docs: false }).catch(() => {});
  await browser?.close();
  await gateway?.child.stop();
  await camera?.child.stop();
});

test("device card from the driver's own info file", async () => {
  const rowsEl = view().locator('[data-panel="device-card"]');
  await waitFor(async () => (await rowsEl.getAttribute("data-loaded")) === "true", "device_info read");
  const row = async (key) => rowsEl.locator(`dd[data-row="${key}"]`).textContent();
  assert.equal(await row("name"), "synthetic_camera");
  assert.equal(await row("uuid"), "4b1d7c52-9e1f-4a52-8d3e-6f0a2c9b7e11");
  assert.equal(await row("manufacturer"), "rr-gateway tests (0c6f8a3e-2d41-4b7f-9a15-3e8d2b6c4f70)");
  assert.equal(await row("model"), "synthetic-opencv-source (9f2a6d84-7c3b-4e15-b2a9-51d8e0c7f362)");
  assert.equal(await row("serial"), "SYN-0001");
  assert.equal(await row("description"), "OpenCV camera driver fed by a synthetic frame source (test)");
  assert.equal(await row("classes"), "camera (webcam)");
  assert.match(await row("types"), /^com\.robotraconteur\.imaging\.Camera(, |$)/);
  // the generic member view stays below the panels
  await view().locator('.member[data-member="frame_stream"]').waitFor();
  assert.ok(await view().locator('.member[data-member="capture_frame"]').count());
});

test("camera panel: capabilities, camera_info and param_info readable", async () => {
  const dd = (key) => panel().locator(`.camera-info dd[data-row="${key}"]`);
  await waitFor(async () => (await dd("capabilities").count()) > 0, "capabilities read");
  assert.equal(await dd("capabilities").textContent(), "still | stream | preview");
  await waitFor(async () => (await dd("calibration.K").count()) > 0, "camera_info read");
  assert.match(await dd("device").textContent(), /^synthetic_camera \(4b1d7c52-/);
  assert.match(await dd("calibration.image_size").textContent(), /320.*240/);
  assert.match(await dd("calibration.K").textContent(), /300/);
  const params = panel().locator("table.param-info tbody tr");
  await waitFor(async () => (await params.count()) === 6, "six parameters");
  // parameter, its DataType as type text, description
  assert.deepEqual(await panel().locator('tr[data-param="focus"] td').allTextContents(),
    ["focus", "double", "Focus of the camera (CAP_PROP_FOCUS property)"]);
});

test("start streaming from the panel: preview, raw and compressed streams show the frames sent", async () => {
  await panel().locator('button[data-action="start_streaming"]').click();
  const state = panel().locator("output.camera-state");
  await waitFor(async () => /\bstreaming\b/.test((await state.getAttribute("data-flags")) || ""), "camera_state streaming", 15000);
  assert.match(await state.getAttribute("data-flags"), /^ready \| streaming$/);
  // the camera_state card below shares the panel's wire connection (one per wire): its value, no error
  const stateCard = view().locator('.member[data-member="camera_state"]');
  await waitFor(async () => /state_flags: ready \| streaming[,}]/.test(await stateCard.locator(".stream output.value").textContent()),
    "the camera_state card's value");
  assert.ok(await stateCard.locator(".member-error").isHidden(), `camera_state card: ${await stateCard.locator(".member-error").textContent()}`);

  // preview_stream: JPEG quality 70
  const preview = await framesMatch(live(), 3, 8, "preview");
  assert.ok(preview.max <= 40 && preview.mean <= 4, `preview within JPEG's error: ${JSON.stringify(preview)}`);
  assert.equal(await live().getAttribute("data-encoding"), "jpeg");
  assert.match(await live().locator(".frame-status").textContent(), /^320×240 jpeg · [\d.]+ fps · [\d.]+ m?s old/);
  await screenshot(panel(), "dashboard-camera.png");

  // frame_stream: raw bgr888, every pixel as sent
  await panel().locator("select.camera-stream").selectOption("frame_stream");
  await waitFor(async () => (await live().getAttribute("data-encoding")) === "bgr888", "raw frames drawn", 15000);
  const raw = await framesMatch(live(), 2, 0, "raw");
  assert.equal(raw.max, 0, `raw frame ${raw.k} equal to the frame sent: ${JSON.stringify(raw)}`);
  const k1 = raw.k;
  const raw2 = await framesMatch(live(), 2, 0, "raw");
  assert.equal(raw2.max, 0);
  assert.notEqual(raw2.k, k1, "the frames move on");

  // frame_stream_compressed: JPEG quality 100
  await panel().locator("select.camera-stream").selectOption("frame_stream_compressed");
  await waitFor(async () => (await live().getAttribute("data-encoding")) === "jpeg", "compressed frames drawn", 15000);
  const jpeg = await framesMatch(live(), 2, 8, "compressed");
  assert.ok(jpeg.max <= 16 && jpeg.mean <= 2, `compressed within JPEG's error: ${JSON.stringify(jpeg)}`);

  // the generic pipe card below draws the same pictures (an endpoint of its own beside the panel's)
  const pipeCard = view().locator('.member[data-member="frame_stream"]');
  await pipeCard.locator("button", { hasText: /^Connect$/ }).click();
  const pipeFig = pipeCard.locator(".frame-view").first();
  await pipeFig.waitFor({ timeout: 60000 });
  const fromCard = await framesMatch(pipeFig, 2, 0, "frame_stream card");
  assert.equal(fromCard.max, 0, `the pipe card's frame ${fromCard.k} equal to the frame sent`);
  assert.equal(await pipeFig.getAttribute("data-encoding"), "bgr888");
  await pipeCard.locator("button", { hasText: /^Disconnect$/ }).click();
  assert.deepEqual(pageErrors.map(String), []);
});

test("capture frame and capture compressed from the panel", async () => {
  const captured = panel().locator(".camera-capture .frame-view");
  await panel().locator('button[data-action="capture_frame"]').click();
  await waitFor(async () => (await captured.getAttribute("data-encoding")) === "bgr888", "captured raw frame drawn");
  const raw = await compareWithPattern(captured.locator("canvas"), camera.info, 0);
  assert.equal(raw.max, 0, `captured frame ${raw.k} equal to the frame sent`);
  await panel().locator('button[data-action="capture_frame_compressed"]').click();
  await waitFor(async () => (await captured.getAttribute("data-encoding")) === "jpeg", "captured JPEG drawn");
  const jpeg = await compareWithPattern(captured.locator("canvas"), camera.info, 8);
  assert.ok(jpeg.max <= 16, `captured JPEG within its error: ${JSON.stringify(jpeg)}`);
});

test("stop streaming from the panel: the flags say so and the picture stops", async () => {
  await panel().locator('button[data-action="stop_streaming"]').click();
  const state = panel().locator("output.camera-state");
  await waitFor(async () => (await state.getAttribute("data-flags")) === "ready", "camera_state not streaming", 15000);
  // Frames already on their way when the flags changed may still be drawn (more of them on a crowded
  // machine): the picture has stopped once no frame came for 1.5 s, which a stream never allows.
  const drawn = await num(live(), "data-drawn");
  let count = drawn, since = Date.now();
  await waitFor(async () => {
    const n = await num(live(), "data-drawn");
    if (n !== count) [count, since] = [n, Date.now()];
    return Date.now() - since >= 1500;
  }, "no new frame for 1.5 s after stop_streaming", 30000);
  console.log(`# ${count - drawn} frame(s) drawn after the flags said not streaming`);
  // a second stop is the driver's own error, shown in place
  await panel().locator('button[data-action="stop_streaming"]').click();
  await waitFor(async () => !(await panel().locator(".camera-error").isHidden()), "the driver's error shown");
  assert.match(await panel().locator(".camera-error").textContent(), /stop_streaming: RobotRaconteur\.InvalidOperation.*Not streaming/);
  assert.deepEqual(pageErrors.map(String), []);
});
