// Standard images in the dashboard (issue 41): test/browser/devices/image_service.py (the official
// Python library) behind rr-gateway, in headless Chromium. Every raw ImageEncoding and PNG/JPEG
// CompressedImages arrive on wires; the picture drawn must equal the RGBA the service worked out for
// each (bilinear bayer and the depth colour map included; JPEG within a few levels of OpenCV's own
// decoding). The bad frames one by one: the wire's picture says what is wrong with each and keeps the
// last good frame's pixels, and the next good frame clears the error. The same pictures appear for a
// property, a function result and a map of images (one picture per key). Screenshots go to
// $RR_ARTIFACTS (and docs/img with RR_DOCS_SCREENSHOTS=1).

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import { settings, startGateway, launchChromium, apiDevices, waitFor } from "./harness.mjs";
import { startDevice, screenshot, canvasPixels, pixelDiff } from "./std_support.mjs";

const s = settings();
let service, gateway, browser, page;
const pageErrors = [];

const card = (name) => page.locator(`.member[data-member="${name}"]`).first();
const frameOf = (name) => card(name).locator(".frame-view").first();
// a wire's picture appears with its first frame: before it, no attribute ("" and 0)
const attr = async (loc, name) => ((await loc.count()) ? (await loc.getAttribute(name)) ?? "" : "");
const num = async (loc, name) => Number((await attr(loc, name)) || 0);

/** Sends a case to the service (stdin) and resolves with its answer (reference picture and all). */
async function send(name) {
  const answer = service.child.jsonLine("sent", 20000);
  service.child.proc.stdin.write(`${JSON.stringify({ case: name })}\n`);
  const a = await answer;
  assert.equal(a.sent, name);
  a.rgba = a.reference ? Array.from(Buffer.from(a.reference, "base64")) : null;
  return a;
}

/** Sends a good case and waits until the wire's picture is that frame; returns the answer. */
async function showGood(name) {
  const wire = name === "png" || name === "jpeg" ? "compressed" : "image";
  const fig = frameOf(wire);
  const drawn = await num(fig, "data-drawn");
  const a = await send(name);
  await waitFor(async () => (await num(fig, "data-drawn")) > drawn && (await attr(fig, "data-encoding")) === name,
    `${name} drawn on the ${wire} wire`, 15000);
  a.wire = wire;
  return a;
}

async function assertPicture(fig, a, what) {
  const px = await canvasPixels(fig.locator("canvas"));
  assert.deepEqual([px.width, px.height], [a.width, a.height], `${what}: size`);
  const d = pixelDiff(px.data, a.rgba, a.tolerance);
  assert.equal(d.over, 0, `${what}: ${d.over} samples differ by more than ${a.tolerance} (max ${d.max}, mean ${d.mean.toFixed(2)})`);
}

before(async () => {
  assert.ok(s.gateway, "RR_GATEWAY must be set");
  service = await startDevice("image_service.py", ["--max-lifetime", "240"], { stdin: "pipe" });
  gateway = await startGateway(s, { images: service.info.url }, 0, ["--no-demo", "--no-discovery"]);
  await waitFor(async () => (await apiDevices(gateway.base)).find((d) => d.name === "images")?.state === "connected",
    "images connected", 30000);
  browser = await launchChromium();
  page = await (await browser.newContext({ viewport: { width: 1366, height: 1000 } })).newPage();
  page.on("pageerror", (e) => pageErrors.push(e));
  await page.goto(`${gateway.base}/#/images`);
  await card("image").waitFor({ timeout: 60000 });
  await card("compressed").waitFor();
});

after(async () => {
  if (page) await screenshot(page, "std-images-end.png", { docs: false }).catch(() => {});
  await browser?.close();
  await gateway?.child.stop();
  service?.child.proc.stdin.end();
  await service?.child.stop();
});

test("every raw ImageEncoding and PNG/JPEG drawn as the reference decoding says", async () => {
  const cases = service.info.cases.filter((c) => !c.startsWith("bad_"));
  assert.ok(cases.length >= 26, `the service serves ${cases.length} good cases`);
  const failed = [];
  for (const name of cases) {
    const a = await showGood(name);
    const fig = frameOf(a.wire);
    try {
      await assertPicture(fig, a, name);
      if (name.startsWith("depth_")) assert.match(await fig.locator(".frame-status").textContent(), /depth -?[\d.]+–[\d.]+/);
    } catch (e) {
      failed.push(e.message);
    }
  }
  assert.deepEqual(failed, []);
  // a depth frame shows its range; the status names the encoding and the frame rate
  await showGood("depth_u16");
  assert.match(await frameOf("image").locator(".frame-status").textContent(), /^16×12 depth_u16 · depth 537–2166( · |$)/);
  await screenshot(card("image"), "std-images-depth.png");
  assert.deepEqual(pageErrors.map(String), []);
});

test("bad frames, one by one: what is wrong is shown, the last good frame stays, the next good one clears it", async () => {
  const expectations = {
    bad_data_too_short: /data has 599 bytes; 12 rows of step 50 need 600/,
    bad_unknown_encoding: /encoding 4660 is not an ImageEncoding value/,
    bad_step_too_small: /step 45 is less than a row of 16 rgb888 pixels \(48 bytes\)/,
    bad_zero_size: /the image is 0×12/,
    bad_not_raw: /encoding compressed has no pixel layout/,
    bad_corrupt_jpeg: /jpeg image could not be decoded/,
    bad_unknown_format: /unknown compressed image format \(first bytes 00 01 02 03\)/,
  };
  for (const [bad, message] of Object.entries(expectations)) {
    const compressed = bad === "bad_corrupt_jpeg" || bad === "bad_unknown_format";
    const good = await showGood(compressed ? "png" : "rgb888");
    const fig = frameOf(good.wire);
    assert.ok(await fig.locator(".frame-error").isHidden(), `${bad}: no error before`);
    const errors = await num(fig, "data-errors");
    const a = await send(bad);
    await waitFor(async () => (await num(fig, "data-errors")) > errors, `${bad}: its error shown`);
    assert.equal(await attr(fig, "data-error-code"), a.error, bad);
    const text = await fig.locator(".frame-error").textContent();
    assert.match(text, message, `${bad}: ${text}`);
    assert.match(text, /showing the last good frame/);
    await assertPicture(fig, good, `${bad}: the last good frame kept`);
    if (bad === "bad_step_too_small") await screenshot(card("image"), "std-images-bad-frame.png");
    // the next good frame takes the error away
    const drawn = await num(fig, "data-drawn");
    await send(good.sent);
    await waitFor(async () => (await num(fig, "data-drawn")) > drawn, `${bad}: the next good frame drawn`);
    assert.ok(await fig.locator(".frame-error").isHidden(), `${bad}: error cleared by the next good frame`);
  }
  assert.deepEqual(pageErrors.map(String), []);
});

test("pictures in a property, a function result and a map of images", async () => {
  const mono = await send("mono8");
  const good = await showGood("rgb888");  // the service's last raw frame (still, capture, capture_pair[0])
  // property: read (again) after the frame was set
  const still = card("still");
  const stillFig = still.locator(".frame-view").first();
  const reads = await num(still.locator("output.value"), "data-reads");
  // the card read the property once when it opened: wait for the picture of this read, not that one's
  const stillDrawn = await num(stillFig, "data-drawn");
  await still.locator("button", { hasText: /^Read$/ }).click();
  await waitFor(async () => (await num(still.locator("output.value"), "data-reads")) > reads, "still read");
  assert.match(await still.locator("output.value").textContent(), /^16×12 rgb888, 600 bytes$/);
  await waitFor(async () => (await num(stillFig, "data-drawn")) > stillDrawn, "the property's picture of this read");
  await assertPicture(stillFig, good, "property still");
  // function result
  const capture = card("capture");
  await capture.locator("button", { hasText: /^Call$/ }).click();
  const capFig = capture.locator(".frame-view").first();
  await waitFor(async () => (await num(capFig, "data-drawn")) >= 1, "the function result's picture");
  await assertPicture(capFig, good, "function capture");
  // Image{int32}: one picture per key
  const pair = card("capture_pair");
  await pair.locator("button", { hasText: /^Call$/ }).click();
  const item = (key) => pair.locator(`.image-item[data-key="${key}"] .frame-view`);
  await waitFor(async () => (await num(item("0"), "data-drawn")) >= 1 && (await num(item("1"), "data-drawn")) >= 1, "both pictures of the map");
  await assertPicture(item("0"), good, "capture_pair[0]");
  await assertPicture(item("1"), mono, "capture_pair[1]");
  assert.equal(await attr(item("1"), "data-encoding"), "mono8");
  assert.match(await pair.locator("output.result").textContent(), /^\{0: 16×12 rgb888, 600 bytes, 1: 16×12 mono8, 216 bytes\}$/);
  assert.deepEqual(pageErrors.map(String), []);
});
