#!/usr/bin/env node
// Benchmark (issue 54): a point cloud sensor (test/browser/devices/point_cloud.py on the official
// library: a PointCloudSensor, PointCloudf of --points points at --rate Hz; 300,000 points are 3.6 MB a
// cloud) behind rr-gateway, its point cloud panel open in one headless Debian Chromium tab for a while.
// Prints figures, asserts nothing: per sampling period the clouds the gateway got from the device and
// those a full client queue made it drop (its /metrics), the clouds the page received and drew per second, the clouds skipped for newer ones (newest wins: skipped, never queued),
// the time to copy each cloud out of the client package's objects on the page and to colour it in the
// Worker (median and 95th percentile), how busy the page's main thread was (CDP TaskDuration over the
// wall time) and its JS heap. Not a test: heavy for CI's two cores.
//
//   node bench/point_cloud_rate.mjs --gateway build/debug/server/app/rr-gateway [--points 300000] [--rate 10]
//        [--seconds 60] [--every 10] [--json FILE]
//
// Needs what the browser tests need: web/dist (wasm-client/build.sh, web/build.sh), web/node_modules,
// .venv with robotraconteur and robotraconteurcompanion (scripts/setup.sh), /usr/bin/chromium.

import fs from "node:fs";
import path from "node:path";
import { ROOT, settings, startGateway, launchChromium, apiDevices, waitFor } from "../test/browser/harness.mjs";
import { startDevice } from "../test/browser/std_support.mjs";

const args = process.argv.slice(2);
const opt = (name, def) => {
  const i = args.indexOf(`--${name}`);
  return i >= 0 ? args[i + 1] : def;
};
const points = Number(opt("points", 300000));
const rate = Number(opt("rate", 10));
const seconds = Number(opt("seconds", 60));
const every = Number(opt("every", 10));
const gatewayPath = opt("gateway", process.env.RR_GATEWAY || path.join(ROOT, "build/debug/server/app/rr-gateway"));
const jsonOut = opt("json", null);

const s = { ...settings(), gateway: gatewayPath };
let device, gateway, browser;
const quantile = (xs, q) => {
  const v = xs.filter(Number.isFinite).sort((a, b) => a - b);
  return v.length ? v[Math.min(v.length - 1, Math.floor(q * v.length))] : NaN;
};
const f1 = (x) => (Number.isFinite(x) ? x.toFixed(1) : "-");

try {
  console.log(`[bench] point cloud of ${points} points at ${rate} Hz (PointCloudf), ${seconds} s`);
  device = await startDevice("point_cloud.py", ["--points", String(points), "--rate", String(rate), "--services", "cloud",
    "--max-lifetime", String(seconds + 180)]);
  gateway = await startGateway(s, { cloud: device.info.urls.cloud }, 0, ["--no-demo", "--no-discovery"]);
  await waitFor(async () => (await apiDevices(gateway.base)).find((d) => d.name === "cloud")?.state === "connected", "sensor connected", 60000);
  browser = await launchChromium();
  const context = await browser.newContext({ viewport: { width: 1280, height: 900 } });
  const page = await context.newPage();
  const errors = [];
  page.on("pageerror", (e) => errors.push(String(e)));
  await page.goto(`${gateway.base}/#/cloud`);
  const panel = page.locator('[data-panel="point-cloud"]');
  await panel.waitFor({ timeout: 60000 });
  await waitFor(async () => Number(await panel.getAttribute("data-clouds")) > 0, "a cloud drawn", 120000);
  // every drawn cloud's timings, recorded in the page as the panel writes them
  await panel.evaluate((el) => {
    window.__clouds = [];
    new MutationObserver(() => {
      const d = el.dataset;
      window.__clouds.push({ t: performance.now(), seqno: Number(d.seqno), decodeMs: Number(d.decodeMs), packMs: Number(d.packMs), skipped: Number(d.skipped) });
    }).observe(el, { attributes: true, attributeFilter: ["data-clouds"] });
  });
  const cdp = await context.newCDPSession(page);
  await cdp.send("Performance.enable");
  const read = async () => {
    const metrics = Object.fromEntries((await cdp.send("Performance.getMetrics")).metrics.map((m) => [m.name, m.value]));
    const [clouds, received, skipped, seqno] = await Promise.all(["data-clouds", "data-received", "data-skipped", "data-seqno"]
      .map(async (a) => Number((await panel.getAttribute(a)) || 0)));
    const drawnList = await page.evaluate(() => window.__clouds.splice(0));
    // the gateway's own counters: packets it forwarded to its clients and those a client's full queue refused
    const prom = await fetch(`${gateway.base}/metrics`).then((r) => r.text()).catch(() => "");
    const counter = (name) => Number(new RegExp(`^${name}\\{device="cloud"\\} (\\S+)$`, "m").exec(prom)?.[1] ?? NaN);
    return { t: performance.now() / 1000, clouds, received, skipped, seqno, task: metrics.TaskDuration, heap: metrics.JSHeapUsedSize, drawnList,
      forwarded: counter("rr_gateway_device_pipe_packets_total"), drops: counter("rr_gateway_device_drops_total") };
  };
  const samples = [await read()];
  const all = [];
  const end = performance.now() + seconds * 1000;
  console.log("| t s | gateway in/s | gateway drops | page received/s | drawn/s | skipped | copy ms p50/p95 | colour ms p50/p95 | main thread busy | heap MB |");
  console.log("|---|---|---|---|---|---|---|---|---|---|");
  while (performance.now() < end) {
    await new Promise((r) => setTimeout(r, Math.min(every * 1000, end - performance.now())));
    const a = samples.at(-1), b = await read();
    samples.push(b);
    all.push(...b.drawnList);
    const dt = b.t - a.t;
    const pack = b.drawnList.map((x) => x.packMs), col = b.drawnList.map((x) => x.decodeMs);
    console.log(`| ${Math.round(seconds - (end - performance.now()) / 1000)} | ${f1((b.forwarded - a.forwarded) / dt)} | ${b.drops - a.drops} | ${f1((b.received - a.received) / dt)} | `
      + `${f1((b.clouds - a.clouds) / dt)} | ${b.skipped - a.skipped} | ${f1(quantile(pack, 0.5))}/${f1(quantile(pack, 0.95))} | `
      + `${f1(quantile(col, 0.5))}/${f1(quantile(col, 0.95))} | ${Math.round((100 * (b.task - a.task)) / dt)} % | ${f1(b.heap / 1e6)} |`);
  }
  const first = samples[0], last = samples.at(-1), span = last.t - first.t;
  const summary = {
    points, rate, seconds: span,
    gatewayInPerS: (last.forwarded - first.forwarded) / span, gatewayDrops: last.drops - first.drops, receivedPerS: (last.received - first.received) / span, drawnPerS: (last.clouds - first.clouds) / span,
    skipped: last.skipped - first.skipped,
    copyMs: { p50: quantile(all.map((x) => x.packMs), 0.5), p95: quantile(all.map((x) => x.packMs), 0.95) },
    colourMs: { p50: quantile(all.map((x) => x.decodeMs), 0.5), p95: quantile(all.map((x) => x.decodeMs), 0.95) },
    mainThreadBusy: (last.task - first.task) / span, heapMB: last.heap / 1e6, pageErrors: errors,
  };
  console.log(`\n[bench] over ${f1(span)} s: gateway in ${f1(summary.gatewayInPerS)}/s (${summary.gatewayDrops} dropped for a full client queue), received ${f1(summary.receivedPerS)}/s, drawn ${f1(summary.drawnPerS)}/s, `
    + `${summary.skipped} skipped for newer; copy ${f1(summary.copyMs.p50)}/${f1(summary.copyMs.p95)} ms, colour (worker) ${f1(summary.colourMs.p50)}/${f1(summary.colourMs.p95)} ms (p50/p95); `
    + `main thread busy ${Math.round(100 * summary.mainThreadBusy)} %; heap ${f1(summary.heapMB)} MB; page errors ${errors.length}`);
  if (jsonOut) fs.writeFileSync(jsonOut, JSON.stringify({ summary, samples }, null, 1));
} finally {
  await browser?.close();
  await gateway?.child.stop();
  await device?.child.stop();
}
