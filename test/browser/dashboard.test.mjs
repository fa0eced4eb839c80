// The dashboard (web/dist) in headless Chromium against a live rr-gateway with its demo devices
// (create, webcam) and Reynard the Robot behind it. Run by ctest (test/browser/CMakeLists.txt) with
// `node --test`; screenshots go to $RR_ARTIFACTS.

import { test, before, after, afterEach } from "node:test";
import assert from "node:assert/strict";
import http from "node:http";
import fs from "node:fs";
import path from "node:path";
import { settings, startReynard, startGateway, launchChromium, apiDevices, waitFor, webRequire, TcpRelay } from "./harness.mjs";

const s = settings();
let reynard, relay, gateway, browser, page, chat;
const pageErrors = [];

/** Reynard's web UI chat as a socket.io client (what reynard's own page is): it repeats every text
 * Reynard says as a chat message, which Reynard publishes as its RR event new_message. */
function startChat(httpUrl) {
  const { io } = webRequire("socket.io-client");
  const socket = io(httpUrl.replace(/\/$/, ""), { transports: ["polling"], reconnection: true });
  const said = [];
  socket.on("say", (text) => {
    said.push(text);
    socket.emit("new_message", text);
  });
  return { socket, said };
}

/** Saves a screenshot of the whole page (fullPage) or of the laptop-sized viewport. */
async function shot(name, fullPage = true) {
  fs.mkdirSync(s.artifacts, { recursive: true });
  await page.screenshot({ path: path.join(s.artifacts, `${name}.png`), fullPage });
}

function card(member, within = page) {
  return within.locator(`.member[data-member="${member}"]`).first();
}

async function openDevice(name) {
  await page.goto(`${gateway.base}/#/${name}`);
  await page.locator(`.device-view[data-device="${name}"] .badge`).nth(1).filter({ hasText: "connected" }).waitFor({ timeout: 60000 });
}

async function readout(locatorCard, series) {
  const v = await locatorCard.locator(`.plot-readout [data-series="${series}"]`).first().getAttribute("data-value", { timeout: 15000 });
  return Number(v);
}

async function callFunction(c, args = {}) {
  const result = c.locator("output.result");
  const before = Number((await result.getAttribute("data-calls")) || 0);
  for (const [name, value] of Object.entries(args)) await c.locator(`[aria-label="${name}"]`).fill(String(value));
  await c.locator("button[type=submit]").click();
  await waitFor(async () => Number((await result.getAttribute("data-calls")) || 0) > before || !(await c.locator(".member-error").isHidden()),
    "the call to finish");
  const error = c.locator(".member-error");
  assert.ok(await error.isHidden(), `call failed: ${await error.textContent()}`);
  return result.textContent();
}

/** A short digest of a canvas's pixels (in the page). */
function canvasDigest(locator) {
  return locator.evaluate((cv) => {
    const d = cv.getContext("2d").getImageData(0, 0, cv.width, cv.height).data;
    let sum = 0, lit = 0, blue96 = 0;
    for (let i = 0; i < d.length; i += 4) {
      sum = (sum * 31 + d[i] + 3 * d[i + 1] + 7 * d[i + 2]) >>> 0;
      if (d[i] + d[i + 1] + d[i + 2] > 30) lit++;
      if (d[i + 2] === 96) blue96++;
    }
    return { sum, lit, blue96, width: cv.width, height: cv.height };
  });
}

before(async () => {
  assert.ok(s.gateway, "RR_GATEWAY (path of rr-gateway) must be set");
  reynard = await startReynard(s);
  relay = new TcpRelay(reynard.info.port);
  await relay.listen();
  gateway = await startGateway(s, { reynard: `rr+tcp://127.0.0.1:${relay.port}/?service=reynard` });
  await waitFor(async () => (await apiDevices(gateway.base)).every((d) => d.state === "connected"), "every device connected", 30000);
  chat = startChat(reynard.info.http_url);
  await waitFor(() => chat.socket.connected, "socket.io connected to Reynard's web UI");
  browser = await launchChromium();
  const context = await browser.newContext({ viewport: { width: 1366, height: 900 } });
  page = await context.newPage();
  page.on("pageerror", (e) => pageErrors.push(e));
});

after(async () => {
  chat?.socket.close();
  await browser?.close();
  const status = gateway ? await gateway.child.stop() : null;
  await relay?.drop();
  await reynard?.child.stop();
  if (status) assert.equal(status.code, 0, `rr-gateway exited with ${JSON.stringify(status)}`);
});

afterEach(() => {
  assert.deepEqual(pageErrors.splice(0).map(String), [], "uncaught errors in the page");
});

test("lists the devices with their live state", async () => {
  await page.goto(`${gateway.base}/`);
  for (const name of ["create", "webcam", "reynard"]) {
    await page.locator(`#device-list li[data-device="${name}"][data-state="connected"]`).waitFor({ timeout: 60000 });
  }
  assert.equal(await page.locator("#device-list li[data-device]").count(), 3);
  assert.match(await page.locator('#device-list li[data-device="reynard"] .device-type').textContent(),
    /experimental\.reynard_the_robot\.Reynard/);
  await shot("01-devices");
});

test("shows the service definition with linked types", async () => {
  await openDevice("reynard");
  const defs = page.locator(".definitions");
  await defs.locator('details[data-service="experimental.reynard_the_robot"]').waitFor();
  assert.match(await defs.textContent(), /wire ReynardState state \[readonly\]/);
  // the state wire's type links to the struct declaration
  const link = card("state").locator(".member-type a.type-link", { hasText: "ReynardState" });
  await link.click();
  await page.locator(".robdef-line.flash", { hasText: "struct ReynardState" }).waitFor();
});

test("reynard: setting color reads back", async () => {
  await openDevice("reynard");
  const color = card("color");
  await waitFor(async () => (await color.locator("output.value").textContent()).startsWith("["), "color read");
  await color.locator('[aria-label="color value"]').fill("0.2, 0.4, 0.6");
  await color.locator("button", { hasText: "Set" }).click();
  await waitFor(async () => (await color.locator("output.value").textContent()) === "[0.2, 0.4, 0.6]", "color read back");
  // the device has it (through the gateway's JSON API, not the page)
  const r = await (await fetch(`${gateway.base}/api/devices/reynard/properties/color`)).json();
  assert.deepEqual(r.value.map((x) => Math.round(x * 10) / 10), [0.2, 0.4, 0.6]);
  // a value the device refuses shows its error in place and changes nothing
  await color.locator('[aria-label="color value"]').fill("2, 0, 0");
  await color.locator("button", { hasText: "Set" }).click();
  await waitFor(async () => !(await color.locator(".member-error").isHidden()), "error shown");
  assert.match(await color.locator(".member-error").textContent(), /RobotRaconteur\.\w+/);
  assert.equal(await color.locator("output.value").textContent(), "[0.2, 0.4, 0.6]");
  await shot("02-reynard-color");
});

test("reynard: teleport changes the plotted state", async () => {
  await openDevice("reynard");
  const state = card("state");
  const chart = state.locator(".plot-chart canvas").first();
  await waitFor(async () => Number(await state.locator(".plot").getAttribute("data-samples")) > 5, "state samples");
  await callFunction(card("teleport"), { x: -0.4, y: 0.1 });
  await waitFor(async () => Math.abs((await readout(state, "robot_position[0]")) + 400) < 1, "x = -400 mm plotted");
  const before = await canvasDigest(chart);
  await callFunction(card("teleport"), { x: 0.5, y: -0.2 });
  await waitFor(async () => Math.abs((await readout(state, "robot_position[0]")) - 500) < 1, "x = 500 mm plotted");
  assert.ok(Math.abs((await readout(state, "robot_position[1]")) + 200) < 1, "y = -200 mm plotted");
  await waitFor(async () => (await canvasDigest(chart)).sum !== before.sum, "the plot redrawn");
  await shot("03-reynard-teleport");
});

test("reynard: say shows in the event log (new_message)", async () => {
  await openDevice("reynard");
  const text = `hello from the dashboard ${Date.now()}`;
  await callFunction(card("say"), { message: text });
  await waitFor(() => chat.said.includes(text), "Reynard saying it in its web UI");
  const entry = page.locator('.event-log li[data-member="new_message"]', { hasText: text });
  await entry.waitFor({ timeout: 60000 });
  assert.equal(await card("new_message").locator("output.count").textContent(), "1");
  await shot("04-reynard-event-log");
  await page.evaluate(() => window.scrollTo(0, 0));
  await shot("04-reynard-viewport", false);
});

test("webcam: streamed frames render on a canvas", async () => {
  await openDevice("webcam");
  const webcams = card("Webcams");
  await webcams.locator('button.suggestion[data-index="0"]').click();
  const cam = page.locator('.child-object[data-path="Webcams[0]"]');
  await cam.waitFor();
  await callFunction(card("StartStreaming", cam));
  const pipe = card("FrameStream", cam);
  await pipe.locator("button", { hasText: "Connect" }).click();
  const canvas = pipe.locator("canvas.image");
  await waitFor(async () => Number(await canvas.getAttribute("data-frames")) >= 3, "3 frames");
  const a = await canvasDigest(canvas);
  assert.deepEqual([a.width, a.height], [320, 240]);
  assert.ok(a.lit > 1000, "the frame is not blank");
  // camera 0's background has blue = 96 everywhere (server/demo/webcam_image.hpp): channels and rows
  // are where they belong
  assert.ok(a.blue96 > 0.8 * 320 * 240, `${a.blue96} background pixels`);
  await waitFor(async () => (await canvasDigest(canvas)).sum !== a.sum, "the next frame drawn");
  await shot("05-webcam-stream");
  await shot("05-webcam-viewport", false);
  // a function's image result is drawn too
  const capture = card("CaptureFrame", cam);
  await callFunction(capture);
  const c = await canvasDigest(capture.locator("canvas.image"));
  assert.deepEqual([c.width, c.height], [320, 240]);
  assert.ok(c.blue96 > 0.8 * 320 * 240, `${c.blue96} background pixels in the captured frame`);
  // memory viewer: the multidim buffer drawn as an image after CaptureFrameToBuffer
  await callFunction(card("CaptureFrameToBuffer", cam));
  const mem = card("multidimbuffer", cam);
  await mem.locator('[aria-label="count"]').fill("240, 320, 3");
  await mem.locator("button", { hasText: "Read" }).click();
  await waitFor(async () => Number(await mem.locator(".memory-table").getAttribute("data-count")) === 240 * 320 * 3, "memory read");
  const m = await canvasDigest(mem.locator("canvas.image"));
  assert.ok(m.lit > 1000, "the memory image is not blank");
  assert.ok(m.blue96 > 0.8 * 320 * 240, `${m.blue96} background pixels (column-major [y, x, c] drawn right)`);
  await pipe.locator("button", { hasText: "Disconnect" }).click();
  await callFunction(card("StopStreaming", cam));
});

test("create: driving moves the plotted distance; play_callback is answered", async () => {
  await openDevice("create");
  const dist = card("DistanceTraveled");
  const d0 = await readout(dist, "DistanceTraveled");
  const cb = card("play_callback");
  await cb.locator('[aria-label="play_callback reply"]').fill("60, 16, 64, 16");
  await cb.locator("input[type=checkbox]").check();
  await callFunction(card("StartStreaming"));
  await callFunction(card("Drive"), { velocity: 200, radius: 32767 });
  await waitFor(async () => (await readout(dist, "DistanceTraveled")) >= d0 + 100, "distance +100 mm plotted");
  // the packets wire, decoded, plots it too
  const packets = card("packets");
  await waitFor(async () => (await readout(packets, "DistanceTraveled")) >= d0 + 100, "packets plot the distance");
  await shot("06-create-drive");
  await callFunction(card("Drive"), { velocity: 0, radius: 32767 });
  // while streaming the device calls play_callback (every 5 s, and on bumps); our reply comes back
  // in the packets (song length and first byte)
  await waitFor(async () => (await readout(packets, "song_length")) === 4, "the reply's length in the packets", 20000);
  assert.equal(await readout(packets, "song_first"), 60);
  await page.locator('.event-log li[data-member="play_callback"]', { hasText: "-> [60, 16, 64, 16]" }).first().waitFor();
  await callFunction(card("StopStreaming"));
});

test("a device the gateway does not have shows the connect error in place", async () => {
  await page.goto(`${gateway.base}/#/nosuch`);
  const banner = page.locator('.device-view[data-device="nosuch"] .device-error');
  await banner.waitFor({ state: "visible", timeout: 60000 });
  assert.match(await banner.textContent(), /rr\+ws:\/\/127\.0\.0\.1:\d+\/\?service=nosuch: RobotRaconteur\.\w+/);
  await page.locator('.event-log li[data-kind="error"]').first().waitFor();
});

test("a page from a disallowed Origin is refused", async () => {
  const other = http.createServer((req, res) => {
    res.writeHead(200, { "Content-Type": "text/html" });
    res.end("<!doctype html><title>elsewhere</title>");
  });
  await new Promise((r) => other.listen(0, "127.0.0.1", r));
  const origin = `http://127.0.0.1:${other.address().port}`;
  try {
    const r = await fetch(`${gateway.base}/api/devices`, { headers: { Origin: origin } });
    assert.equal(r.status, 403);
    const p = await browser.newPage();
    await p.goto(`${origin}/`);
    const result = await p.evaluate(async (port) => {
      const ws = await new Promise((resolve) => {
        const w = new WebSocket(`ws://127.0.0.1:${port}/?service=reynard`, "robotraconteur.robotraconteur.com");
        w.onopen = () => { w.close(); resolve("open"); };
        w.onerror = () => resolve("refused");
      });
      let fetched;
      try { fetched = (await fetch(`http://127.0.0.1:${port}/api/devices`)).status; } catch { fetched = "refused"; }
      return { ws, fetched };
    }, gateway.port);
    assert.deepEqual(result, { ws: "refused", fetched: "refused" });
    await p.close();
  } finally {
    other.close();
  }
});

test("keeps working when a device drops and comes back", async () => {
  await openDevice("reynard");
  await relay.drop();
  await page.locator('#device-list li[data-device="reynard"]:not([data-state="connected"])').waitFor({ timeout: 60000 });
  await page.locator(".device-error").waitFor({ state: "visible" });
  // a request while the device is away fails in place
  const color = card("color");
  await color.locator("button", { hasText: "Read" }).click();
  await waitFor(async () => !(await color.locator(".member-error").isHidden()), "the read's error shown");
  assert.match(await color.locator(".member-error").textContent(), /RobotRaconteur\.\w+/);
  await shot("07-reynard-down");
  await relay.listen();
  await page.locator('#device-list li[data-device="reynard"][data-state="connected"]').waitFor({ timeout: 60000 });
  await page.locator(".device-error").waitFor({ state: "hidden", timeout: 60000 });
  const samples = async () => Number(await card("state").locator(".plot").getAttribute("data-samples"));
  const n = await waitFor(samples, "state samples after the return", 30000);
  await waitFor(async () => (await samples()) > n + 5, "the state wire streaming again", 30000);
  await callFunction(card("teleport"), { x: 0.25, y: 0 });
  await waitFor(async () => Math.abs((await readout(card("state"), "robot_position[0]")) - 250) < 1, "x = 250 mm plotted", 15000);
  await shot("08-reynard-back");
});

test("reconnects when the gateway itself restarts", async () => {
  await openDevice("create");
  const session = page.locator('.device-view[data-device="create"] .badge').nth(1);
  const port = gateway.port;
  const status = await gateway.child.stop();
  assert.equal(status.code, 0, `rr-gateway exited with ${JSON.stringify(status)}`);
  await page.locator('#gateway-status[data-state="failed"]').waitFor({ timeout: 60000 });
  await waitFor(async () => (await session.textContent()) !== "connected", "the page's session down");
  gateway = await startGateway(s, { reynard: `rr+tcp://127.0.0.1:${relay.port}/?service=reynard` }, port);
  await page.locator('#gateway-status[data-state="connected"]').waitFor({ timeout: 60000 });
  await waitFor(async () => (await session.textContent()) === "connected", "the page's session back", 30000);
  const dist = card("DistanceTraveled");
  const samples = async () => Number(await dist.locator(".plot").getAttribute("data-samples"));
  const n = await waitFor(samples, "distance samples after the restart");
  await waitFor(async () => (await samples()) > n + 3, "the property polled again");
  await shot("09-gateway-back");
});
