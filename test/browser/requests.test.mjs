// What the dashboard asks the gateway for, counted for 30 s in headless Chromium (issue 40): it asks
// GET api/features once and then only for what the gateway serves. Two gateways, both without logins:
// A with discovery on (the default), B with --no-discovery. Each page must see no HTTP error answer at
// all (in particular no api/discovered or api/whoami 404, once or repeated) and no console error;
// A's page polls api/discovered, B's never asks for it; neither asks api/whoami (no logins).

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import { settings, startGateway, launchChromium, apiDevices, waitFor } from "./harness.mjs";

const s = settings();
const WATCH_MS = 30000;
let withDiscovery, withoutDiscovery, browser;

before(async () => {
  assert.ok(s.gateway, "RR_GATEWAY (path of rr-gateway) must be set");
  [withDiscovery, withoutDiscovery] = await Promise.all([startGateway(s), startGateway(s, {}, 0, ["--no-discovery"])]);
  for (const g of [withDiscovery, withoutDiscovery])
    await waitFor(async () => (await apiDevices(g.base)).every((d) => d.state === "connected"), "demo devices connected", 30000);
  browser = await launchChromium();
});

after(async () => {
  await browser?.close();
  for (const g of [withDiscovery, withoutDiscovery]) {
    const status = g ? await g.child.stop() : null;
    if (status) assert.equal(status.code, 0, `rr-gateway exited with ${JSON.stringify(status)}`);
  }
});

/** Opens the dashboard of `gateway` and records, for WATCH_MS, every HTTP answer and console error. */
async function watch(gateway) {
  const page = await browser.newPage();
  const answers = [];  // {path, status}
  const problems = [];  // console errors, uncaught errors, failed requests
  page.on("response", (r) => answers.push({ path: new URL(r.url()).pathname, status: r.status() }));
  page.on("console", (m) => { if (m.type() === "error") problems.push(`console: ${m.text()}`); });
  page.on("pageerror", (e) => problems.push(`uncaught: ${e}`));
  page.on("requestfailed", (r) => problems.push(`failed: ${r.method()} ${r.url()}: ${r.failure()?.errorText}`));
  await page.goto(`${gateway.base}/`);
  await page.locator('#device-list li[data-device="create"][data-state="connected"]').waitFor({ timeout: 60000 });
  await page.waitForTimeout(WATCH_MS);
  // What was seen until now (closing the page aborts requests in flight, which is not the page's doing).
  const seen = { answers: answers.slice(), problems: problems.slice() };
  await page.close();
  const count = (p) => seen.answers.filter((a) => a.path === p).length;
  return { ...seen, count };
}

/** What is wrong with one page's 30 s, as sentences (empty: nothing). */
function problemsOf(name, { answers, problems, count }) {
  const out = [];
  const tally = (list) => {
    const m = new Map();
    for (const x of list) m.set(x, (m.get(x) || 0) + 1);
    return [...m].map(([what, n]) => `${name}: ${n} x ${what}`);
  };
  out.push(...tally(answers.filter((a) => a.status >= 400).map((a) => `${a.status} ${a.path}`)));
  out.push(...tally(problems));
  if (count("/api/features") !== 1) out.push(`${name}: api/features asked ${count("/api/features")} times, not once`);
  if (count("/api/whoami") !== 0) out.push(`${name}: api/whoami asked ${count("/api/whoami")} times without logins`);
  if (count("/api/devices") < WATCH_MS / 1000 / 2) out.push(`${name}: the device list polled only ${count("/api/devices")} times`);
  return out;
}

test("the dashboard asks for what each gateway serves, and nothing answers 404 or logs an error (30 s)", async () => {
  const [a, b] = await Promise.all([watch(withDiscovery), watch(withoutDiscovery)]);
  const wrong = [...problemsOf("discovery on", a), ...problemsOf("--no-discovery", b)];
  // Polled every 2 s where discovery is on; never asked where it is off.
  if (a.count("/api/discovered") < WATCH_MS / 2000 / 2) wrong.push(`discovery on: api/discovered polled ${a.count("/api/discovered")} times`);
  if (b.count("/api/discovered") !== 0) wrong.push(`--no-discovery: api/discovered asked ${b.count("/api/discovered")} times`);
  assert.deepEqual(wrong, [], "requests, answers and console of the dashboard over 30 s");
  // The page's section follows: shown with discovery, hidden without (checked on fresh pages).
  for (const [g, shown] of [[withDiscovery, true], [withoutDiscovery, false]]) {
    const page = await browser.newPage();
    // The section starts hidden, so "hidden" means something only once the page has read api/features:
    // mark the moment its answer's JSON is read (the page acts on it in the same microtask run, before
    // any poll of waitForFunction) rather than pausing for a while.
    await page.addInitScript(() => {
      const json = Response.prototype.json;
      Response.prototype.json = async function () {
        const v = await json.call(this);
        if (new URL(this.url).pathname.endsWith("/api/features")) window.__featuresRead = true;
        return v;
      };
    });
    await page.goto(`${g.base}/`);
    await page.locator('#device-list li[data-device="create"]').waitFor({ timeout: 60000 });
    if (shown) await page.locator("section.discovered").waitFor({ state: "visible", timeout: 60000 });
    else {
      await page.waitForFunction(() => window.__featuresRead === true, null, { timeout: 20000 });
      assert.ok(await page.locator("section.discovered").isHidden(), "the Discovered section is hidden without discovery");
    }
    await page.close();
  }
});
