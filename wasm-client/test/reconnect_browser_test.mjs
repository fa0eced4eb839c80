// Reconnecting subscriptions in headless Chromium (reconnect.html runs reconnect_checks.mjs in the page)
// through rr-gateway in front of rr_interop_service. The page and its WebSocket come through a TCP
// proxy the test controls, so that the page's origin is the proxy's (the gateway allows its own pages)
// and the network between page and gateway can be cut silently. The page asks the test to restart the
// device, restart the gateway, cut and restore the network, and drop connections (window.rrControl).
//
// With --target direct the RR WebSocket goes straight to rr_interop_service --websocket instead (the page
// still comes from the gateway, both through the same proxy port). With --checks timeouts the page runs
// timeout_checks.mjs instead (heartbeats, receive and connect timeouts: their bounds are the checks, so
// that run is labelled `timing`).
//
// Every check the page was asked for must have run: one that did not (e.g. the memory check without a
// heap figure) fails the test rather than passing it by omission.
//
// Usage: node reconnect_browser_test.mjs --interop-service PATH --gateway PATH [--target gateway|direct]
//        [--checks reconnect|timeouts] [--reconnects N]
// Exit: 0 passed, 1 a check failed, 2 setup failed, 77 Chromium, playwright-core or emscripten absent.
import { dirname, join } from "node:path";
import { fileURLToPath } from "node:url";
import { CHROMIUM, chromiumOrSkip } from "./chromium_setup.mjs";
import { arg, cutProxy, freePort, gateway, interopService, stopAll } from "./reconnect_harness.mjs";

const here = dirname(fileURLToPath(import.meta.url));
const pkgRoot = join(here, "..");
const pw = chromiumOrSkip();

let browser;
let code = 2;
try {
  const target = arg("--target", "gateway");
  const checks = arg("--checks", "reconnect");
  const svc = await interopService(arg("--interop-service"), await freePort());
  const gw = await gateway(arg("--gateway"), await freePort(), svc.tcpUrl);
  await gw.start(pkgRoot);
  // gateway: page and RR WebSocket both to the gateway. direct: the page from the gateway, the RR
  // WebSocket (an upgrade request) straight to the service; both through one proxy port, so that the
  // page's origin is the proxy's, which the service takes as its own (same Host).
  const proxy = await cutProxy(target === "direct"
    ? (first) => (/^upgrade:\s*websocket/im.test(first.toString("latin1")) ? svc.port : gw.port) : gw.port);
  const actions = { restartDevice: () => svc.restart(), cut: () => proxy.cut(), restore: () => proxy.restore(),
    dropAll: () => proxy.dropAll() };
  if (target === "gateway") actions.restartGateway = () => gw.restart();
  if (checks === "timeouts") for (const a of ["restartDevice", "restartGateway", "dropAll"]) delete actions[a];
  // reconnect_checks.mjs: first connection, one per disruption (cut and restore make one), memory (dropAll), close()
  const expected = checks === "timeouts" ? 4
    : 2 + ["restartDevice", "restartGateway", "cut", "dropAll"].filter((a) => actions[a]).length;
  browser = await pw.launch({ executablePath: CHROMIUM, headless: true,
    args: ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run", "--disable-background-networking",
      "--disable-component-update", "--disable-sync", "--js-flags=--expose-gc", "--enable-precise-memory-info"] });
  const page = await browser.newPage();
  page.on("console", (m) => console.log(`  ${m.text()}`));
  page.on("pageerror", (e) => console.log(`  [pageerror] ${e.message}`));
  await page.exposeFunction("rrControl", async (a) => {
    if (!actions[a]) throw new Error(`unknown action ${a}`);
    await actions[a]();
  });
  const origin = `http://127.0.0.1:${proxy.port}`;
  const url = `${origin}/test/reconnect.html?url=${encodeURIComponent(`rr+ws://127.0.0.1:${proxy.port}/?service=interop`)}` +
    `&controls=${Object.keys(actions).join(",")}&reconnects=${arg("--reconnects", "100")}&checks=${checks}`;
  console.log(`== chromium ${browser.version()}, ${target}, ${checks} checks: ${url}`);
  await page.goto(url);
  await page.waitForFunction(() => window.__result?.done === true, null, { timeout: 450000, polling: 200 });
  const r = await page.evaluate(() => window.__result);
  if (process.env.SUBS_SNAPSHOT) {  // debugging aid: a heap snapshot of the page after the checks
    const cdp = await page.context().newCDPSession(page);
    const chunks = [];
    cdp.on("HeapProfiler.addHeapSnapshotChunk", (e) => chunks.push(e.chunk));
    await cdp.send("HeapProfiler.enable");
    await cdp.send("HeapProfiler.collectGarbage");
    await cdp.send("HeapProfiler.takeHeapSnapshot", { reportProgress: false });
    (await import("node:fs")).writeFileSync(process.env.SUBS_SNAPSHOT, chunks.join(""));
  }
  for (const f of r.failed) console.log(`  FAIL ${f.name}: ${f.error}`);
  const ran = r.passed.length + r.failed.length;
  console.log(`== chromium: ${r.passed.length} passed, ${r.failed.length} failed` +
    (ran === expected ? "" : `; FAIL: ${ran} checks ran, ${expected} expected`));
  code = r.failed.length || ran !== expected ? 1 : 0;
} catch (e) {
  console.error(`browser test: ${e.message}`);
  code = 2;
} finally {
  await browser?.close();
  stopAll();
}
process.exit(code);
