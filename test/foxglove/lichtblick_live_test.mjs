// Lichtblick (the open-source Foxglove Studio) connected live to rr-gateway's Foxglove WebSocket
// (docs/foxglove.md), in headless Chromium: what a user sees after "Open connection → Foxglove
// WebSocket → ws://<gateway>/foxglove". Devices: the demo create (streaming packets) and the official
// camera driver's synthetic camera (a standard Image pipe, so also a foxglove.RawImage channel).
// Checked: the camera's picture in an Image panel (many saturated colours, from the live
// `camera/frame_stream/foxglove` channel), a Plot of a wire field drawing a line, Raw Messages showing
// a live packet with its schema name, the topics list naming the channels and schemas, and the
// Problems list holding nothing about the connection, channels, schemas or services.
//
//   LICHTBLICK_WEB=~/.cache/rr-gateway/lichtblick-web RR_GATEWAY=… node test/foxglove/lichtblick_live_test.mjs
//
// Without a Lichtblick web build (scripts/build-lichtblick.sh) the test reports SKIP (77), as the
// recording test does. Env as the browser tests: RR_GATEWAY, RR_PYTHON, RR_ARTIFACTS (screenshots;
// RR_DOCS_SCREENSHOTS=1 also writes docs/img/lichtblick-live.png).
import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";
import { settings, startGateway, launchChromium, apiDevices, waitFor } from "../browser/harness.mjs";
import { DEVICES, startDevice, screenshot } from "../browser/std_support.mjs";
import { lichtblickWebOrSkip, serveLichtblick, gatewayApi, shotPixels } from "../browser/lichtblick_support.mjs";

const s = settings();
const web = lichtblickWebOrSkip();

const work = fs.mkdtempSync(path.join(os.tmpdir(), "rr-lichtblick-live-"));
let camera, gateway, server, browser, page;
const pageErrors = [];

const LAYOUT = {
  configById: {
    "RawMessages!wire": { topicPath: "create/packets", diffEnabled: false, diffMethod: "custom", diffTopicPath: "", showFullMessageForDiff: false },
    "Plot!wire": {
      paths: [{ value: "create/packets.time.nanoseconds", enabled: true, timestampMethod: "receiveTime" }],
      showXAxisLabels: true, showYAxisLabels: true, showLegend: true, legendDisplay: "floating",
      showPlotValuesInLegend: true, isSynced: true, xAxisVal: "timestamp",
    },
    "Image!cam": { imageMode: { imageTopic: "camera/frame_stream/foxglove" } },
  },
  globalVariables: {},
  userNodes: {},
  playbackConfig: { speed: 1 },
  layout: {
    direction: "row",
    first: { direction: "column", first: "RawMessages!wire", second: "Plot!wire", splitPercentage: 50 },
    second: "Image!cam",
    splitPercentage: 45,
  },
};

const serve = () => serveLichtblick(web, LAYOUT);
const api = (method, p, body) => gatewayApi(gateway.base, method, p, body);
const pixels = (locator) => shotPixels(page, locator);

const panel = (id) => page.locator(`[data-testid="panel-mouseenter-container ${id}"]`);

before(async () => {
  assert.ok(s.gateway, "RR_GATEWAY must be set");
  camera = await startDevice("camera_synthetic.py",
    ["--camera-info", path.join(DEVICES, "synthetic_camera_info.yml"), "--width", "160", "--height", "120", "--fps", "10",
      "--max-lifetime", "240"]);
  server = await serve();
  const config = path.join(work, "gateway.yaml");
  // Lichtblick is served from another origin than the gateway: allowed, as a lab would configure it.
  fs.writeFileSync(config, ["gateway:", `  allowed_origins: ["http://127.0.0.1:${server.address().port}"]`, ""].join("\n"));
  gateway = await startGateway(s, { camera: camera.info.url }, 0, ["--no-discovery", "--config", config]);
  await waitFor(async () => {
    const d = await apiDevices(gateway.base);
    return ["camera", "create"].every((n) => d.find((x) => x.name === n)?.state === "connected");
  }, "camera and create connected", 40000);
  for (const [device, fn] of [["camera", "start_streaming"], ["create", "StartStreaming"]]) {
    const r = await api("POST", `/api/devices/${device}/functions/${fn}`, {});
    assert.ok(r.status < 300, `${device} ${fn}: ${r.status} ${JSON.stringify(r.body)}`);
  }
  browser = await launchChromium();
  page = await (await browser.newContext({ viewport: { width: 1400, height: 900 } })).newPage();
  page.setDefaultTimeout(60000);
  page.on("pageerror", (e) => pageErrors.push(String(e)));
});

after(async () => {
  if (page) await screenshot(page, "lichtblick-live-end.png", { docs: false }).catch(() => {});
  await browser?.close();
  server?.close();
  await gateway?.child.stop();
  await camera?.child.stop();
  fs.rmSync(work, { recursive: true, force: true });
});

test("Lichtblick live over the Foxglove WebSocket: the camera's picture, a plot of a wire, raw messages", { timeout: 400000 }, async () => {
  const ws = `ws://127.0.0.1:${gateway.port}/foxglove`;
  await page.goto(`http://127.0.0.1:${server.address().port}/?ds=foxglove-websocket&ds.url=${encodeURIComponent(ws)}`);

  // Raw Messages: a live packet of the create's wire, with its schema name
  await waitFor(async () => /experimental\.create\.Create\.packets/.test(await panel("RawMessages!wire").innerText()),
    "Raw Messages shows a live create/packets message", 90000, 500);
  assert.match(await panel("RawMessages!wire").innerText(), /value/);

  // Image panel: the synthetic camera's picture (many saturated colours) from the foxglove.RawImage channel
  await waitFor(async () => {
    const img = await pixels(panel("Image!cam"));
    const colours = new Map();
    for (let i = 0; i < img.data.length; i += 4) {
      const [r, g, b] = img.data.slice(i, i + 3);
      if (Math.max(r, g, b) - Math.min(r, g, b) < 80) continue;  // greys: background, text
      const key = `${r >> 5},${g >> 5},${b >> 5}`;
      colours.set(key, (colours.get(key) || 0) + 1);
    }
    return [...colours.values()].filter((n) => n > img.width * img.height / 100).length >= 5;
  }, "the Image panel shows the camera's picture", 90000, 1000);

  // Plot: the wire's field drawn as a line (the series' colour on many columns of the chart)
  await waitFor(async () => {
    const plot = await pixels(panel("Plot!wire"));
    const cols = new Set();
    for (let i = 0; i < plot.data.length; i += 4) {
      const [r, g, b] = plot.data.slice(i, i + 3);
      if (b > 150 && b - r > 60 && b - g > 20) cols.add((i / 4) % plot.width);
    }
    return cols.size > plot.width / 4;
  }, "the Plot draws the wire's values", 90000, 1000);

  // Topics: the live channels with their schema names
  await page.locator('[data-testid="topics-left"]').click();
  const sidebar = page.locator('[data-testid="sidebar-left"]');
  await waitFor(async () => (await sidebar.innerText()).includes("camera/frame_stream/foxglove"), "the topics list", 30000);
  const topics = await sidebar.innerText();
  for (const t of ["create/packets", "create/Bump", "camera/frame_stream", "camera/frame_stream/foxglove",
    "experimental.create.Create.packets", "foxglove.RawImage"])
    assert.ok(topics.includes(t), `the topics list shows ${t}:\n${topics}`);
  await screenshot(page, "lichtblick-live.png");  // docs/img with RR_DOCS_SCREENSHOTS=1
  await page.locator('[data-testid="problems-left"]').click();
  await new Promise((r) => setTimeout(r, 500));
  // Problems: none about the connection, channels, schemas or services; a device's own error reading a
  // property (the camera driver's trigger_mode) is reported as such.
  const problems = (await sidebar.innerText()).split("\n").map((l) => l.trim()).filter(Boolean);
  const listed = problems.slice(problems.indexOf("Layouts") + 1);
  const known = [/^parameters not read: /, /^No details provided$/];
  for (const line of listed) assert.ok(known.some((re) => re.test(line)), `an unexpected problem in Lichtblick: ${line}\n${listed.join("\n")}`);
  assert.deepEqual(pageErrors, []);
});
