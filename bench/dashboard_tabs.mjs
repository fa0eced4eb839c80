#!/usr/bin/env node
// Benchmark (issue 41): the official camera driver (test/browser/devices/camera_synthetic.py, its
// OpenCV capture fed by the synthetic source) at 640×480 and 30 fps behind rr-gateway, its picture
// open in N dashboard tabs at once in headless Debian Chromium for a while. Prints figures, asserts
// nothing: per tab and sampling period, the frames received and drawn per second, the frames dropped
// for newer ones (the newest wins: dropped, never queued), the age of the picture shown (from the
// frame's own timestamp), and the page's JS heap (CDP Performance.getMetrics) from the first sample
// to the last. Not a test: too long and too heavy for CI on two cores.
//
//   node bench/dashboard_tabs.mjs --gateway build/debug/server/app/rr-gateway [--tabs 10] [--seconds 300]
//        [--stream preview_stream|frame_stream_compressed|frame_stream] [--fps 30] [--width 640 --height 480]
//        [--every 10] [--json FILE]
//
// Needs what the browser tests need: web/dist (wasm-client/build.sh, web/build.sh), web/node_modules,
// .venv with the camera driver (scripts/setup.sh), /usr/bin/chromium.

import fs from "node:fs";
import path from "node:path";
import { ROOT, settings, startGateway, launchChromium, apiDevices, waitFor } from "../test/browser/harness.mjs";
import { DEVICES, startDevice } from "../test/browser/std_support.mjs";

const args = process.argv.slice(2);
const opt = (name, def) => {
  const i = args.indexOf(`--${name}`);
  return i >= 0 ? args[i + 1] : def;
};
const tabs = Number(opt("tabs", 10));
const seconds = Number(opt("seconds", 300));
const every = Number(opt("every", 10));
const stream = opt("stream", "preview_stream");
const fps = Number(opt("fps", 30));
const width = Number(opt("width", 640)), height = Number(opt("height", 480));
const gatewayPath = opt("gateway", process.env.RR_GATEWAY || path.join(ROOT, "build/debug/server/app/rr-gateway"));
const jsonOut = opt("json", null);

const s = { ...settings(), gateway: gatewayPath };
let camera, gateway, browser;
const quantile = (xs, q) => {
  const v = xs.filter(Number.isFinite).sort((a, b) => a - b);
  return v.length ? v[Math.min(v.length - 1, Math.floor(q * v.length))] : NaN;
};

try {
  console.log(`[bench] camera ${width}×${height} at ${fps} fps, ${stream}, ${tabs} tabs, ${seconds} s`);
  camera = await startDevice("camera_synthetic.py", ["--camera-info", path.join(DEVICES, "synthetic_camera_info.yml"),
    "--width", String(width), "--height", String(height), "--fps", String(fps), "--max-lifetime", String(seconds + 180)]);
  gateway = await startGateway(s, { camera: camera.info.url }, 0, ["--no-demo", "--no-discovery"]);
  await waitFor(async () => (await apiDevices(gateway.base)).find((d) => d.name === "camera")?.state === "connected", "camera connected", 30000);
  browser = await launchChromium();
  const context = await browser.newContext({ viewport: { width: 1280, height: 900 } });
  const pages = [];
  for (let i = 0; i < tabs; i++) {
    const page = await context.newPage();
    const errors = [];
    page.on("pageerror", (e) => errors.push(String(e)));
    await page.goto(`${gateway.base}/#/camera`);
    await page.locator('[data-panel="camera"]').waitFor({ timeout: 30000 });
    if (stream !== "preview_stream") await page.locator("select.camera-stream").selectOption(stream);
    const cdp = await context.newCDPSession(page);
    await cdp.send("Performance.enable");
    pages.push({ page, cdp, errors, samples: [] });
  }
  await pages[0].page.locator('button[data-action="start_streaming"]').click();
  const fig = (p) => p.page.locator(`.camera-live .frame-view`).first();
  await waitFor(async () => Number(await fig(pages[tabs - 1]).getAttribute("data-drawn")) > 0, "frames in the last tab", 30000);

  const read = async (p) => {
    const f = fig(p);
    const [drawn, received, dropped, age] = await Promise.all(["data-drawn", "data-received", "data-dropped", "data-age-ms"]
      .map(async (a) => Number((await f.getAttribute(a)) || 0)));
    const metrics = (await p.cdp.send("Performance.getMetrics")).metrics;
    const heap = metrics.find((m) => m.name === "JSHeapUsedSize")?.value ?? NaN;
    return { t: performance.now() / 1000, drawn, received, dropped, age, heap };
  };
  for (const p of pages) p.samples.push(await read(p));
  const end = performance.now() + seconds * 1000;
  while (performance.now() < end) {
    await new Promise((r) => setTimeout(r, Math.min(every * 1000, end - performance.now())));
    const row = [];
    for (const p of pages) {
      const a = p.samples.at(-1), b = await read(p);
      p.samples.push(b);
      row.push({ drawnPerS: (b.drawn - a.drawn) / (b.t - a.t), receivedPerS: (b.received - a.received) / (b.t - a.t), age: b.age, heapMB: b.heap / 1e6 });
    }
    const f = (xs) => `${quantile(xs, 0).toFixed(1)}/${quantile(xs, 0.5).toFixed(1)}/${quantile(xs, 1).toFixed(1)}`;
    console.log(`[bench] t=${Math.round(seconds - (end - performance.now()) / 1000)} s  received/s ${f(row.map((r) => r.receivedPerS))}`
      + `  drawn/s ${f(row.map((r) => r.drawnPerS))}  age ms ${f(row.map((r) => r.age))}  heap MB ${f(row.map((r) => r.heapMB))}  (min/median/max over tabs)`);
  }
  await pages[0].page.locator('button[data-action="stop_streaming"]').click().catch(() => {});
  const summary = pages.map((p, i) => {
    const first = p.samples[1] ?? p.samples[0], last = p.samples.at(-1);
    const span = last.t - first.t;
    return {
      tab: i, receivedPerS: (last.received - first.received) / span, drawnPerS: (last.drawn - first.drawn) / span,
      dropped: last.dropped, ageMsLast: last.age,
      heapMBFirst: first.heap / 1e6, heapMBLast: last.heap / 1e6, heapMBMax: Math.max(...p.samples.slice(1).map((x) => x.heap)) / 1e6,
      pageErrors: p.errors.length,
    };
  });
  console.log("\n| tab | received/s | drawn/s | dropped | age ms (last) | heap MB first → last (max) | page errors |");
  console.log("|---|---|---|---|---|---|---|");
  for (const r of summary) {
    console.log(`| ${r.tab} | ${r.receivedPerS.toFixed(1)} | ${r.drawnPerS.toFixed(1)} | ${r.dropped} | ${r.ageMsLast} | `
      + `${r.heapMBFirst.toFixed(1)} → ${r.heapMBLast.toFixed(1)} (${r.heapMBMax.toFixed(1)}) | ${r.pageErrors} |`);
  }
  if (jsonOut) fs.writeFileSync(jsonOut, JSON.stringify({ width, height, fps, stream, tabs, seconds, summary, samples: pages.map((p) => p.samples) }, null, 1));
} finally {
  await browser?.close();
  await gateway?.child.stop();
  await camera?.child.stop();
}
