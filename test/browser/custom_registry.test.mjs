// A page's own renderer registry drives the dashboard's drawing, in headless Chromium: a page made
// from the dashboard's index.html whose module (pages/custom_registry.js) starts the dashboard with
// the standard renderers plus its own for the demo webcam's types: a custom type (WebcamImage_size,
// its own text) and a custom picture format (WebcamImage, its own `image` hook, which swaps red and
// blue). The page is served by rr-gateway from a copy of the web root with the page added.

import { test, before, after, afterEach } from "node:test";
import assert from "node:assert/strict";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";
import { fileURLToPath } from "node:url";
import { settings, startGateway, launchChromium, apiDevices, waitFor } from "./harness.mjs";

const s = settings();
const here = path.dirname(fileURLToPath(import.meta.url));
let webRoot, gateway, browser, page;
const pageErrors = [];

const card = (member, within = page) => within.locator(`.member[data-member="${member}"]`).first();

/** Pixels of a canvas: how many have red 96 (the webcam's blue background, swapped by the page's hook) or blue 96. */
function canvasDigest(locator) {
  return locator.evaluate((cv) => {
    const d = cv.getContext("2d").getImageData(0, 0, cv.width, cv.height).data;
    let red96 = 0, blue96 = 0;
    for (let i = 0; i < d.length; i += 4) {
      if (d[i] === 96) red96++;
      if (d[i + 2] === 96) blue96++;
    }
    return { red96, blue96, width: cv.width, height: cv.height };
  });
}

async function callFunction(c) {
  const result = c.locator("output.result");
  const before = Number((await result.getAttribute("data-calls")) || 0);
  await c.locator("button[type=submit]").click();
  await waitFor(async () => Number((await result.getAttribute("data-calls")) || 0) > before, "the call to finish");
  return result.textContent();
}

before(async () => {
  assert.ok(s.gateway, "RR_GATEWAY (path of rr-gateway) must be set");
  webRoot = fs.mkdtempSync(path.join(os.tmpdir(), "rr-custom-page-"));
  fs.cpSync(s.webRoot, webRoot, { recursive: true });
  fs.mkdirSync(path.join(webRoot, "pages"));
  fs.copyFileSync(path.join(here, "pages/custom_registry.js"), path.join(webRoot, "pages/custom_registry.js"));
  const index = fs.readFileSync(path.join(s.webRoot, "index.html"), "utf8");
  const own = index.replace('src="src/main.js"', 'src="pages/custom_registry.js"');
  assert.notEqual(own, index, "index.html starts the dashboard from src/main.js");
  fs.writeFileSync(path.join(webRoot, "custom.html"), own);
  gateway = await startGateway({ ...s, webRoot });
  await waitFor(async () => (await apiDevices(gateway.base)).find((d) => d.name === "webcam")?.state === "connected", "webcam connected", 30000);
  browser = await launchChromium();
  page = await (await browser.newContext({ viewport: { width: 1366, height: 900 } })).newPage();
  page.on("pageerror", (e) => pageErrors.push(e));
  await page.goto(`${gateway.base}/custom.html#/webcam`);
  await page.locator('.device-view[data-device="webcam"] .badge').nth(1).filter({ hasText: "connected" }).waitFor({ timeout: 60000 });
});

after(async () => {
  if (page) {
    fs.mkdirSync(s.artifacts, { recursive: true });
    await page.screenshot({ path: path.join(s.artifacts, "60-custom-registry.png"), fullPage: true }).catch(() => {});
  }
  await browser?.close();
  const status = gateway ? await gateway.child.stop() : null;
  if (webRoot) fs.rmSync(webRoot, { recursive: true, force: true });
  if (status) assert.equal(status.code, 0, `rr-gateway exited with ${JSON.stringify(status)}`);
});

afterEach(() => assert.deepEqual(pageErrors.splice(0).map(String), [], "uncaught errors in the page"));

test("a page's own renderers: a custom type's text and a custom picture format drawn by its hook", async () => {
  await card("Webcams").locator('button.suggestion[data-index="0"]').click();
  const cam = page.locator('.child-object[data-path="Webcams[0]"]');
  await cam.waitFor();
  // the custom type: the page's text for WebcamImage_size
  assert.equal(await callFunction(card("CaptureFrameToBuffer", cam)), "custom size 320 by 240");
  // the custom picture format: a function result drawn by the page's image hook (red and blue swapped)
  const capture = card("CaptureFrame", cam);
  assert.equal(await callFunction(capture), "custom picture 320 by 240");
  const captured = capture.locator("canvas.frame-canvas");
  await waitFor(async () => (await canvasDigest(captured)).red96 > 0.8 * 320 * 240, "the captured frame drawn by the page's hook");
  const c = await canvasDigest(captured);
  assert.deepEqual([c.width, c.height], [320, 240]);
  assert.ok(c.blue96 < 0.2 * 320 * 240, `${c.blue96} pixels with blue 96: the standard drawing, not the page's hook`);
  // and a stream of them: the pipe's frames drawn by the same hook, one FrameView
  await callFunction(card("StartStreaming", cam));
  const pipe = card("FrameStream", cam);
  await pipe.locator("button", { hasText: "Connect" }).click();
  const frames = pipe.locator("figure.frame-view").first();
  await waitFor(async () => Number(await frames.getAttribute("data-received")) >= 3, "3 frames received");
  const streamed = pipe.locator("canvas.frame-canvas");
  await waitFor(async () => (await canvasDigest(streamed)).red96 > 0.8 * 320 * 240, "a streamed frame drawn by the page's hook");
  const plain = pipe.locator("canvas.image:not(.frame-canvas)");
  assert.ok((await plain.count()) === 0 || (await plain.isHidden()), "no plain canvas shown: the registry drew the stream");
  assert.match(await pipe.locator(".stream output.value").textContent(), /^custom picture 320 by 240/);
});

test("the standard renderers are still there: the device card's and definitions' pages work", async () => {
  // the webcam host's WebcamNames (string{int32}) read as usual text
  const names = card("WebcamNames");
  await waitFor(async () => /0: /.test((await names.locator("output.value").textContent()) ?? ""), "WebcamNames read");
});
