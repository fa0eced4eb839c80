// wasm_bench.mjs: the wasm client (wasm-client/dist) against the bench service through the gateway over
// rr+ws (issue 14, the browser row): Nop() and a read of property Value, one call after the other, in
// node (with the `ws` package) and in headless Chromium (playwright-core from web/node_modules, Debian's
// /usr/bin/chromium). Prints one JSON line per (runtime, op) with the keys of bench_common.hpp's
// latency_row: p50/p99/max µs, calls/s, and CPU µs and voluntary context switches per call (node: its
// own process; Chromium: every process of the browser, from /proc).
//
// The page is served by playwright (page.route) under the gateway's origin, so its WebSocket is
// same-origin, with COOP/COEP headers: a cross-origin isolated page gets performance.now() at 5 µs
// resolution instead of 100 µs (the row says whether it was: cross_origin_isolated).
//
// Usage: node bench/wasm_bench.mjs --port GATEWAY_PORT [--service bench] [--count N] [--runtimes node,chromium]
// Exit: 0, 2 on failure, 77 when wasm-client/dist, the ws package, Chromium or playwright-core is missing.
import { existsSync, readFileSync, readdirSync } from "node:fs";
import { createRequire } from "node:module";
import { dirname, extname, join } from "node:path";
import { fileURLToPath, pathToFileURL } from "node:url";

const ROOT = join(dirname(fileURLToPath(import.meta.url)), "..");
const DIST = join(ROOT, "wasm-client", "dist");
const CHROMIUM = "/usr/bin/chromium";
// As test/browser/harness.mjs and wasm-client/test/browser_test.mjs: nothing reaches for the network.
const CHROMIUM_ARGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run", "--disable-background-networking",
  "--disable-component-update", "--disable-sync"];

function arg(name, fallback = null) {
  const i = process.argv.indexOf(name);
  return i > 0 && i + 1 < process.argv.length ? process.argv[i + 1] : fallback;
}
const port = Number(arg("--port"));
const service = arg("--service", "bench");
const count = Number(arg("--count", "2000"));
const warmup = Math.min(200, Math.max(20, Math.floor(count / 10)));
const runtimes = arg("--runtimes", "node,chromium").split(",");
if (!port) {
  console.error("usage: node bench/wasm_bench.mjs --port GATEWAY_PORT [--service bench] [--count N] [--runtimes node,chromium]");
  process.exit(2);
}
const url = `rr+ws://127.0.0.1:${port}/?service=${service}`;

function skip(what) {
  console.error(`[wasm_bench] SKIP: ${what}`);
  process.exit(77);
}
if (!existsSync(join(DIST, "robotraconteur.mjs"))) skip("wasm-client/dist missing (wasm-client/build.sh)");

/** Times `count` calls of op (nop | get) on globalThis.__benchProxy; runs in node and in the page. */
async function timeCalls({ op, count }) {
  const c = globalThis.__benchProxy;
  const call = op === "nop" ? () => c.Nop() : () => c.Value.get();
  const samples = new Array(count);
  const t0 = performance.now();
  for (let i = 0; i < count; i++) {
    const a = performance.now();
    await call();
    samples[i] = (performance.now() - a) * 1000;
  }
  return { samples, wallUs: (performance.now() - t0) * 1000, isolated: globalThis.crossOriginIsolated ?? null };
}

/** CPU µs and voluntary context switches of the processes below `pid` (Chromium's tree), from /proc. */
function treeUsage(pid) {
  const parent = new Map();
  const ticks = new Map();
  for (const d of readdirSync("/proc")) {
    if (!/^\d+$/.test(d)) continue;
    try {
      const stat = readFileSync(`/proc/${d}/stat`, "utf8");
      const f = stat.slice(stat.lastIndexOf(")") + 2).split(" ");
      parent.set(Number(d), Number(f[1]));
      ticks.set(Number(d), Number(f[11]) + Number(f[12]));
    } catch { /* gone */ }
  }
  const inTree = (p) => {
    for (let q = parent.get(p); q; q = parent.get(q)) if (q === pid) return true;
    return false;
  };
  let cpuUs = 0, vcsw = 0;
  for (const [p, t] of ticks) {
    if (!inTree(p)) continue;
    cpuUs += t * 10000;  // USER_HZ = 100 on Linux
    try {
      for (const tid of readdirSync(`/proc/${p}/task`)) {
        const m = /voluntary_ctxt_switches:\s+(\d+)/.exec(readFileSync(`/proc/${p}/task/${tid}/status`, "utf8"));
        if (m) vcsw += Number(m[1]);
      }
    } catch { /* gone */ }
  }
  return { cpuUs, vcsw };
}

function percentile(sorted, q) {
  return sorted.length ? sorted[Math.round(q * (sorted.length - 1))] : 0;
}

function emit(runtime, op, r, before, after) {
  const s = [...r.samples].sort((a, b) => a - b);
  const n = s.length;
  console.log(JSON.stringify({ op, label: `wasm(${runtime})->gateway->ours rr+ws`, runtime, n,
    p50_us: percentile(s, 0.5), p99_us: percentile(s, 0.99), max_us: s[n - 1], ops_per_s: n * 1e6 / r.wallUs,
    client_cpu_us_per_op: (after.cpuUs - before.cpuUs) / n, client_vcsw_per_op: (after.vcsw - before.vcsw) / n,
    cross_origin_isolated: r.isolated }));
}

async function runNode() {
  const req = createRequire(join(ROOT, "wasm-client", "package.json"));
  let WebSocket;
  try {
    WebSocket = req("ws");
  } catch {
    skip("the ws package is missing (wasm-client/node_modules; scripts/setup.sh)");
  }
  const rr = await import(pathToFileURL(join(DIST, "robotraconteur.mjs")).href);
  globalThis.__benchProxy = await rr.connect(url, { timeoutMs: 15000, WebSocket });
  const self = () => {
    const u = process.resourceUsage();
    return { cpuUs: u.userCPUTime + u.systemCPUTime, vcsw: u.voluntaryContextSwitches };
  };
  for (const op of ["nop", "get"]) {
    await timeCalls({ op, count: warmup });
    const before = self();
    const r = await timeCalls({ op, count });
    emit("node", op, r, before, self());
  }
  await globalThis.__benchProxy.$client.close();
}

async function runChromium() {
  const playwright = join(ROOT, "web", "node_modules", "playwright-core");
  if (!existsSync(CHROMIUM)) skip(`${CHROMIUM} missing (scripts/setup.sh)`);
  if (!existsSync(playwright)) skip("playwright-core missing in web/node_modules (scripts/setup.sh)");
  const { chromium } = createRequire(import.meta.url)(playwright);
  const browser = await chromium.launch({ executablePath: CHROMIUM, headless: true, args: CHROMIUM_ARGS });
  try {
    // A page fulfilled by playwright has no address of its own, so Chromium counts it as public and
    // blocks its WebSocket to 127.0.0.1 (Local Network Access) unless the permission is granted.
    const context = await browser.newContext({ permissions: ["local-network-access"] });
    const page = await context.newPage();
    page.on("pageerror", (e) => console.error(`[wasm_bench] page: ${e.message}`));
    const base = `http://127.0.0.1:${port}/__wasm_bench/`;
    const types = { ".html": "text/html", ".mjs": "text/javascript", ".wasm": "application/wasm" };
    await page.route(`${base}**`, (route) => {
      const rel = new URL(route.request().url()).pathname.slice("/__wasm_bench/".length);
      const body = rel === "" ? "<!doctype html><meta charset=utf-8><title>wasm_bench</title>"
        : rel.startsWith("dist/") && !rel.includes("..") && existsSync(join(DIST, rel.slice(5))) ? readFileSync(join(DIST, rel.slice(5)))
          : null;
      if (body === null) return route.fulfill({ status: 404, body: "not found" });
      route.fulfill({ status: 200, body, headers: { "content-type": types[extname(rel)] ?? "text/html",
        "cross-origin-opener-policy": "same-origin", "cross-origin-embedder-policy": "require-corp" } });
    });
    await page.goto(base);
    await page.evaluate(async (u) => {
      const rr = await import(new URL("dist/robotraconteur.mjs", location.href).href);
      globalThis.__benchProxy = await rr.connect(u, { timeoutMs: 15000 });
    }, url);
    const chromiumRoot = process.pid;  // playwright starts Chromium as our child; nothing else is
    for (const op of ["nop", "get"]) {
      await page.evaluate(timeCalls, { op, count: warmup });
      const before = treeUsage(chromiumRoot);
      const r = await page.evaluate(timeCalls, { op, count });
      emit("chromium", op, r, before, treeUsage(chromiumRoot));
    }
    await page.evaluate(() => globalThis.__benchProxy.$client.close());
  } finally {
    await browser.close();
  }
}

try {
  if (runtimes.includes("node")) await runNode();
  if (runtimes.includes("chromium")) await runChromium();
  process.exit(0);
} catch (e) {
  console.error(`[wasm_bench] ${e?.stack ?? e}`);
  process.exit(2);
}
