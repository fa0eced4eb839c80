// Opens rr-gateway recordings in Lichtblick, the open-source Foxglove Studio (issue 44: "opens the
// file in Foxglove"), in headless Chromium, and checks what a user sees there. Recorded: the demo
// `create` device driving (wire `packets`, property `DistanceTraveled`, event `Bump`; both
// encodings), from the dashboard's Record control as a user would (issue 44's "done when"), and the
// official camera driver's `frame_stream` with synthetic frames (json alone) through the JSON API.
// Checked: Raw Messages shows the property's value at the chosen time and a packet, a Plot draws the
// rising distance, the Image panel shows the camera's picture from the foxglove.RawImage channel, the
// Topics list has every channel and schema, and the Problems list names only the robotraconteur
// channels (an encoding Lichtblick does not decode). Then the create file opened from the disk
// (Lichtblick's local file source) and played to the end.
//
//   LICHTBLICK_WEB=/path/to/lichtblick/web/.webpack node test/record/lichtblick_open_test.mjs
//
// LICHTBLICK_WEB is a built Lichtblick web app (scripts/build-lichtblick.sh). Without it the test
// reports SKIP (77): CI cannot build Lichtblick (its sources come from GitHub). The app is served by a
// small static server here, its index.html given a layout through Lichtblick's default-layout
// placeholder; the files are opened as its "remote file" data source (?ds=remote-file&ds.url=…, HTTP
// range requests). Env as the browser tests: RR_GATEWAY, RR_PYTHON, RR_ARTIFACTS (screenshots).
import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";
import { createRequire } from "node:module";
import { ROOT, settings, startGateway, launchChromium, apiDevices, waitFor } from "../browser/harness.mjs";
import { DEVICES, startDevice, screenshot } from "../browser/std_support.mjs";
import { lichtblickWebOrSkip, serveLichtblick, gatewayApi, shotPixels } from "../browser/lichtblick_support.mjs";

const s = settings();
const web = lichtblickWebOrSkip();
const mcapRequire = createRequire(path.join(ROOT, "test/mcap/package.json"));
let McapIndexedReader, zstd;
try {
  ({ McapIndexedReader } = mcapRequire("@mcap/core"));
  zstd = mcapRequire("@foxglove/wasm-zstd");
} catch (e) {
  console.log(`SKIP: test/mcap/node_modules incomplete (run ./scripts/setup.sh): ${e.message}`);
  process.exit(77);
}

const work = fs.mkdtempSync(path.join(os.tmpdir(), "rr-lichtblick-"));
let camera, gateway, server, browser, page;
const files = {};
const pageErrors = [];

/** The layout Lichtblick opens with (its LayoutData: configById + a mosaic tree). */
const LAYOUT = {
  configById: {
    "RawMessages!wire": { topicPath: "create/packets.value", diffEnabled: false, diffMethod: "custom", diffTopicPath: "", showFullMessageForDiff: false },
    "RawMessages!prop": { topicPath: "create/DistanceTraveled.value", diffEnabled: false, diffMethod: "custom", diffTopicPath: "", showFullMessageForDiff: false },
    "Plot!dist": {
      paths: [{ value: "create/DistanceTraveled.value", enabled: true, timestampMethod: "receiveTime" }],
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
    first: { direction: "column", first: "RawMessages!wire", second: "RawMessages!prop", splitPercentage: 50 },
    second: { direction: "column", first: "Plot!dist", second: "Image!cam", splitPercentage: 50 },
    splitPercentage: 40,
  },
};

/** Serves the app (index.html with LAYOUT) and the recordings (/rec/<name>, with byte ranges). */
function serve() {
  return serveLichtblick(web, LAYOUT, (req, res, url) => {
    if (!url.pathname.startsWith("/rec/")) return false;
    const file = files[decodeURIComponent(url.pathname.slice(5))];
    if (!file) { res.writeHead(404); res.end(); return true; }
    const size = fs.statSync(file).size;
    const range = /^bytes=(\d+)-(\d*)$/.exec(req.headers.range || "");
    const headers = { "Accept-Ranges": "bytes", "Content-Type": "application/octet-stream" };
    if (!range) {
      res.writeHead(200, { ...headers, "Content-Length": size });
      fs.createReadStream(file).pipe(res);
      return true;
    }
    const start = Number(range[1]), end = Math.min(range[2] ? Number(range[2]) : size - 1, size - 1);
    if (start > end) { res.writeHead(416, { "Content-Range": `bytes */${size}` }); res.end(); return true; }
    res.writeHead(206, { ...headers, "Content-Length": end - start + 1, "Content-Range": `bytes ${start}-${end}/${size}` });
    fs.createReadStream(file, { start, end }).pipe(res);
    return true;
  });
}

const api = (method, p, body) => gatewayApi(gateway.base, method, p, body);

/** Every message of `file` on topic `topic` with json encoding: [{logTime (bigint), data (parsed)}]. */
async function jsonMessages(file, topic) {
  const buf = fs.readFileSync(file);
  const readable = { size: async () => BigInt(buf.length), read: async (o, n) => buf.subarray(Number(o), Number(o) + Number(n)) };
  const reader = await McapIndexedReader.Initialize({ readable,
    decompressHandlers: { zstd: (data, size) => zstd.decompress(data, Number(size)) } });
  const ids = [...reader.channelsById.values()].filter((c) => c.topic === topic && c.messageEncoding === "json").map((c) => c.id);
  const out = [];
  for await (const m of reader.readMessages({ topics: [topic] }))
    if (ids.includes(m.channelId)) out.push({ logTime: m.logTime, data: JSON.parse(new TextDecoder().decode(m.data)) });
  return out;
}

before(async () => {
  assert.ok(s.gateway, "RR_GATEWAY must be set");
  await zstd.isLoaded;
  camera = await startDevice("camera_synthetic.py",
    ["--camera-info", path.join(DEVICES, "synthetic_camera_info.yml"), "--width", "160", "--height", "120", "--fps", "10",
      "--max-lifetime", "240"]);
  gateway = await startGateway(s, { camera: camera.info.url }, 0, ["--no-discovery", "--recordings-root", work]);
  await waitFor(async () => {
    const d = await apiDevices(gateway.base);
    return ["camera", "create"].every((n) => d.find((x) => x.name === n)?.state === "connected");
  }, "camera and create connected", 40000);
  const started = await api("POST", "/api/devices/camera/functions/start_streaming", {});
  assert.ok(started.status < 300, `start_streaming: ${started.status} ${JSON.stringify(started.body)}`);
  browser = await launchChromium();
  page = await (await browser.newContext({ viewport: { width: 1400, height: 900 } })).newPage();
  page.setDefaultTimeout(60000);  // clicks on a loaded 2-vCPU machine (a CI run beside) took over 30 s
  page.on("pageerror", (e) => pageErrors.push(String(e)));
  page.on("response", (r) => { if (r.status() >= 400) console.log(`# HTTP ${r.status()} ${r.url()}`); });

  // The camera through the JSON API, json alone (what a file meant for Foxglove needs) ...
  const cam = await api("POST", "/api/recordings", { device: "camera", members: ["frame_stream"], encoding: "json" });
  assert.equal(cam.status, 201, `POST /api/recordings camera: ${JSON.stringify(cam.body)}`);
  // ... and create from the dashboard's Record control, both encodings (its default members + the property)
  await page.goto(`${gateway.base}/#/create`);
  const view = page.locator('.device-view[data-device="create"]');
  await view.locator(".badge").nth(1).filter({ hasText: "connected" }).waitFor({ timeout: 60000 });
  const c = view.locator(".record-control");
  await c.locator("details.record-options summary").click();
  await c.locator("button", { hasText: "none" }).click();
  for (const m of ["packets", "Bump", "DistanceTraveled"]) await c.locator(`input[value="${m}"]`).check();
  await c.locator('select[name="record-encoding"]').selectOption("both");
  await c.locator(".record-button").click();
  await c.locator('.record-button[data-action="stop"]').waitFor({ timeout: 60000 });
  // Driven once the recording runs, so the recorded distance rises (the demo Create stops at a wall
  // after about 7 s: driven earlier, a slow start recorded it standing there)
  const drive = await api("POST", "/api/devices/create/functions/Drive", { args: { velocity: 200, radius: 32767 } });
  assert.equal(drive.status, 200, `Drive: ${JSON.stringify(drive.body)}`);
  await new Promise((r) => setTimeout(r, 7000));  // the property is polled every second
  await c.locator(".record-button").click();
  await c.locator('.record-button[data-action="record"]').waitFor({ timeout: 60000 });
  const item = c.locator(".recordings > li").first();
  await waitFor(async () => (await item.getAttribute("data-state")) === "stopped", "the dashboard lists the recording as stopped", 10000);
  files["create.mcap"] = path.resolve((await item.locator(".recording-files code").allTextContents())[0]);
  const stopped = await api("POST", `/api/recordings/${cam.body.id}/stop`, {});
  assert.equal(stopped.status, 200, `stop camera: ${JSON.stringify(stopped.body)}`);
  assert.ok(stopped.body.messages > 10, `camera: ${stopped.body.messages} frames recorded`);
  files["camera.mcap"] = stopped.body.files.at(-1);
  await api("POST", "/api/devices/create/functions/Drive", { args: { velocity: 0, radius: 32767 } });
  server = await serve();
});

after(async () => {
  if (page) await screenshot(page, "lichtblick-end.png", { docs: false }).catch(() => {});
  await browser?.close();
  server?.close();
  await gateway?.child.stop();
  await camera?.child.stop();
  fs.rmSync(work, { recursive: true, force: true });
});

/** RFC 3339 with nanoseconds of a log time (ns since the epoch, bigint): Lichtblick's `time=` parameter. */
function rfc3339(ns) {
  const iso = new Date(Number(ns / 1000000n)).toISOString();
  return `${iso.slice(0, 19)}.${String(ns % 1000000000n).padStart(9, "0")}Z`;
}

const pixels = (locator) => shotPixels(page, locator);

const panel = (id) => page.locator(`[data-testid="panel-mouseenter-container ${id}"]`);

test("Lichtblick opens the recordings: topics, raw messages, a plot and the camera image", { timeout: 400000 }, async () => {
  // What the file holds: the DistanceTraveled values (rising: the demo Create was driving) and a packet.
  const distance = await jsonMessages(files["create.mcap"], "create/DistanceTraveled");
  assert.ok(distance.length >= 4, `${distance.length} DistanceTraveled values recorded`);
  const k = Math.floor(distance.length * 2 / 3);
  const expected = distance[k].data.value;
  assert.notEqual(expected, distance[0].data.value, "the distance changed while recording (the Create drove)");
  const packets = await jsonMessages(files["create.mcap"], "create/packets");
  const packetBytes = packets[0].data.value.Data.length;

  const base = `http://127.0.0.1:${server.address().port}`;
  const urls = Object.keys(files).map((f) => `ds.url=${encodeURIComponent(`${base}/rec/${f}`)}`).join("&");
  // time=: the player starts paused just after the chosen DistanceTraveled value
  await page.goto(`${base}/?ds=remote-file&${urls}&time=${encodeURIComponent(rfc3339(distance[k].logTime + 1000n))}`);

  // Raw Messages: the property's value at that time, and a wire packet with its bytes
  await waitFor(async () => (await panel("RawMessages!prop").innerText()).includes(String(expected)),
    `Raw Messages shows DistanceTraveled ${expected}`, 60000);
  const prop = await panel("RawMessages!prop").innerText();
  assert.ok(!distance.filter((m, i) => i !== k && m.data.value !== expected).some((m) => prop.split(/\s+/).includes(String(m.data.value))),
    `Raw Messages shows only the value at the chosen time: ${prop}`);
  await waitFor(async () => (await panel("RawMessages!wire").innerText()).includes(`${packetBytes} items`),
    `Raw Messages shows a packet of ${packetBytes} bytes`, 30000);
  assert.match(await panel("RawMessages!wire").innerText(), /experimental\.create\.Create\.packets/);

  // Plot: a rising line, so its pixels (the series' colour) span many rows of the chart. Waited for
  // (the bound is on a hang): under load Lichtblick draws it seconds later; a fixed 2 s wait failed.
  let rows = new Set();
  let plotHeight = 0;
  const plotRows = async () => {
    const plot = await pixels(panel("Plot!dist"));
    rows = new Set();
    plotHeight = plot.height;
    for (let i = 0; i < plot.data.length; i += 4) {
      const [r, g, b] = plot.data.slice(i, i + 3);
      if (b > 150 && b - r > 60 && b - g > 20) rows.add(Math.floor(i / 4 / plot.width));
    }
    return rows.size > plot.height / 4;
  };
  await waitFor(plotRows, "the plotted line spans a quarter of the chart's rows", 60000, 500).catch(() => {});
  assert.ok(rows.size > plotHeight / 4, `the plotted line spans ${rows.size} of ${plotHeight} rows (rising data)`);

  // Image panel: the synthetic camera's picture (many saturated colours), from the foxglove.* channel
  const img = await pixels(panel("Image!cam"));
  const colours = new Map();
  for (let i = 0; i < img.data.length; i += 4) {
    const [r, g, b] = img.data.slice(i, i + 3);
    if (Math.max(r, g, b) - Math.min(r, g, b) < 80) continue;  // greys: background, text
    const key = `${r >> 5},${g >> 5},${b >> 5}`;
    colours.set(key, (colours.get(key) || 0) + 1);
  }
  const big = [...colours.values()].filter((n) => n > img.width * img.height / 100).length;
  assert.ok(big >= 5, `the Image panel shows the camera's picture: ${big} saturated colours`);

  // Topics: every channel, with its schema name
  await page.locator('[data-testid="topics-left"]').click();
  const sidebar = page.locator('[data-testid="sidebar-left"]');
  await waitFor(async () => (await sidebar.innerText()).includes("camera/frame_stream/foxglove"), "the topics list", 20000);
  const topics = await sidebar.innerText();
  for (const t of ["create/packets", "create/DistanceTraveled", "create/Bump", "camera/frame_stream", "camera/frame_stream/foxglove",
    "experimental.create.Create.packets", "foxglove.RawImage"])
    assert.ok(topics.includes(t), `the topics list shows ${t}:\n${topics}`);

  // Problems: only the robotraconteur channels (an encoding Lichtblick does not decode) and the two
  // files' overlapping times; nothing about the json channels, their schemas or the file structure.
  await page.locator('[data-testid="problems-left"]').click();
  await new Promise((r) => setTimeout(r, 500));
  const problems = (await sidebar.innerText()).split("\n").map((l) => l.trim()).filter(Boolean);
  const known = [/^Error in topic (\S+) \(channel \d+\): Unsupported encoding robotraconteur$/, /^Unsupported encoding robotraconteur$/,
    /^Received message on channel \d+ without prior channel info$/, /^No details provided$/,
    /^MCAP time overlap detected\./, /^Check the time range of the MCAPs$/];
  const listed = problems.slice(problems.indexOf("Layouts") + 1);
  for (const line of listed) assert.ok(known.some((re) => re.test(line)), `an unexpected problem in Lichtblick: ${line}\n${listed.join("\n")}`);
  const undecoded = listed.map((l) => known[0].exec(l)?.[1]).filter(Boolean).sort();
  assert.deepEqual(undecoded, ["create/Bump", "create/DistanceTraveled", "create/packets"],
    "the robotraconteur channels, and only they, are reported (the camera was recorded in json alone)");
  await screenshot(page, "lichtblick-recording.png");  // docs/img with RR_DOCS_SCREENSHOTS=1
  assert.deepEqual(pageErrors, []);
});

// The other way a user opens a file: from the disk. "Open local file" (the File System Access picker,
// which Playwright cannot answer) and dropping a file on the window both give the file to Lichtblick's
// local MCAP source (McapLocalDataSourceFactory, read from a Blob: another reader than the remote
// file's HTTP ranges); the drop listener's hidden file input (data-puppeteer-file-upload, kept by
// Lichtblick for its own browser tests) takes the file the way a drop does.
test("Lichtblick opens a recording from the disk (its local file source), played to the end", { timeout: 300000 }, async () => {
  const distance = await jsonMessages(files["create.mcap"], "create/DistanceTraveled");
  const last = String(distance.at(-1).data.value);
  const base = `http://127.0.0.1:${server.address().port}`;
  await page.goto(`${base}/`);
  await page.locator("input[data-puppeteer-file-upload]").setInputFiles(files["create.mcap"]);
  await page.getByText(path.basename(files["create.mcap"])).first().waitFor({ timeout: 60000 });  // the app bar names it
  // The player opens the file paused at its start; Play runs it to the end (about 8 s at speed 1). A
  // click while the file is still loading can be lost, so Play is pressed again while it shows.
  const play = page.locator('button[title="Play"]');
  await waitFor(async () => {
    if ((await panel("RawMessages!prop").innerText()).split(/\s+/).includes(last)) return true;
    if (await play.count()) await play.click({ timeout: 5000 }).catch(() => {});
    return false;
  }, `Raw Messages shows the last recorded DistanceTraveled ${last} once played to the end`, 120000, 1000);
  assert.match(await panel("RawMessages!wire").innerText(), /experimental\.create\.Create\.packets/);
  await page.locator('[data-testid="problems-left"]').click();
  await new Promise((r) => setTimeout(r, 500));
  const problems = await page.locator('[data-testid="sidebar-left"]').innerText();
  assert.doesNotMatch(problems, /chunk|message index|time range/i, `no problem with the file's structure:\n${problems}`);
  await screenshot(page, "lichtblick-local-file.png", { docs: false });
  assert.deepEqual(pageErrors, []);
});
