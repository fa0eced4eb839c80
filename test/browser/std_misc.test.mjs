// The clock, event log, billboard and resource panels (issue 54) on devices served by the official
// library (test/browser/devices/misc_devices.py) behind rr-gateway with logins (alice: operator, bob:
// viewer): the clock's time and its offset from the browser's clock (the device runs 30 s ahead), its
// local time and zone; the event log's messages as the device holds them, new ones arriving on its pipe,
// filtered by words and by level; the billboard's text; the stored resources listed per bucket, Info
// and Download giving exactly the device's bytes; a viewer's log (live messages; the stored ones need the
// call right, refused in place); the JointTrajectory and PIDParam renderers on a device's property and
// function result (pixels drawn, other pixels for another trajectory); a clock without time_utc
// and a log without getf_eventlog_messages fall back to the generic view. No page error. Screenshots to
// $RR_ARTIFACTS (docs/img with RR_DOCS_SCREENSHOTS=1).

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import crypto from "node:crypto";
import fs from "node:fs";
import { launchChromium, waitFor } from "./harness.mjs";
import { startDevice, screenshot, canvasPixels, pixelDiff } from "./std_support.mjs";
import { gatewayWithLogins, loggedInPage, panelOf } from "./std_sensor_support.mjs";

const OFFSET_S = 30;
let misc, oldClock, oldLog, gw, browser, operator;
const pageErrors = [];

before(async () => {
  misc = await startDevice("misc_devices.py", ["--clock-offset", String(OFFSET_S), "--max-lifetime", "250"]);
  oldClock = await startDevice("misc_devices.py", ["--without-member", "time_utc", "--max-lifetime", "250"]);
  oldLog = await startDevice("misc_devices.py", ["--without-member", "getf_eventlog_messages", "--max-lifetime", "250"]);
  const u = misc.info.urls;
  gw = await gatewayWithLogins({ clock: u.clock, log: u.log, sign: u.billboard, store: u.storage, planner: u.planner, oldclock: oldClock.info.urls.clock, oldlog: oldLog.info.urls.log });
  browser = await launchChromium();
  operator = await loggedInPage(browser, gw.gateway.base, "alice", "clock", pageErrors);
});

after(async () => {
  await browser?.close();
  await gw?.gateway.child.stop();
  for (const d of [misc, oldClock, oldLog]) await d?.child.stop();
  if (gw?.tmp) fs.rmSync(gw.tmp, { recursive: true, force: true });
});

async function open(page, device, name) {
  await page.goto(`${gw.gateway.base}/#/${device}`);
  const p = panelOf(page, device, name);
  await p.waitFor({ timeout: 60000 });
  return p;
}

test("clock: the device's time, its offset from the browser's clock, local time and zone", async () => {
  const p = await open(operator, "clock", "clock");
  const row = (k) => p.locator(`dd[data-row="${k}"]`);
  // time_utc (offset), time_local and clock_info (timezone) each come on their own: wait for every row asserted
  await waitFor(async () => (await row("offset").count()) === 1 && (await row("time_local").count()) === 1 && (await row("timezone").count()) === 1, "clock rows", 30000);
  // the device runs 30 s ahead; its time is older than that by the delivery when it arrives
  const offsetMs = Number(await p.getAttribute("data-offset-ms"));
  assert.ok(offsetMs > (OFFSET_S - 3) * 1000 && offsetMs <= OFFSET_S * 1000 + 50, `offset ${offsetMs} ms`);
  assert.match(await row("offset").textContent(), /^\+(2[7-9]|30)\.\d{3} s$/);
  assert.match(await row("time_utc").textContent(), /^\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d(\.\d+)?Z$/);
  assert.match(await row("time_local").textContent(), /^\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d(\.\d+)?\+02:00 Europe\/Berlin$/);
  assert.equal(await row("timezone").textContent(), "+02:00 (Europe/Berlin)");
  assert.equal(await row("clock_type").textContent(), "system_rtc_clock");
  // live: the time moves on
  const first = await row("time_utc").textContent();
  await waitFor(async () => (await row("time_utc").textContent()) !== first, "the clock ticking");
  await screenshot(p, "dashboard-clock.png");
  assert.deepEqual(pageErrors, []);
});

test("event log: the device's messages, new ones live, filtered by words and level", async () => {
  const p = await open(operator, "log", "eventlog");
  // the stored messages come from getf_eventlog_messages (data-ready once added), the live ones from the pipe
  await waitFor(async () => (await p.getAttribute("data-ready")) === "true" && Number(await p.getAttribute("data-messages")) >= 50, "the stored messages", 30000);
  const row = (n) => p.locator(`tr[data-number="${n}"] td`);
  assert.deepEqual(await row(30).allTextContents().then((c) => [c[0], c[2], c[3], c[4], c[5]]),
    ["30", "error", "cell3_plc / line / station3", "conveyor jam at station 3", "belt stopped: part stuck at the transfer"]);
  assert.match((await row(30).allTextContents())[1], /^\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d(\.\d+)?Z$/);
  // new messages arrive on the pipe, newest first
  const before = Number(await p.getAttribute("data-messages"));
  await waitFor(async () => Number(await p.getAttribute("data-messages")) > before, "a new message from the pipe", 20000);
  assert.match(await p.locator("tbody tr").first().locator("td").nth(4).textContent(), /^heartbeat \d+$/);
  // filters
  await p.locator('input[name="eventlog-filter"]').fill("conveyor jam");
  await waitFor(async () => (await p.getAttribute("data-shown")) === "5", "5 jams shown");
  assert.deepEqual(await p.locator("tbody tr").evaluateAll((rs) => rs.map((r) => r.dataset.number)), ["50", "40", "30", "20", "10"]);
  await p.locator('input[name="eventlog-filter"]').fill("");
  await p.locator('select[name="eventlog-level"]').selectOption({ label: "warning and above" });
  await waitFor(async () => {
    const levels = await p.locator("tbody tr").evaluateAll((rs) => rs.map((r) => r.dataset.level));
    return levels.length > 5 && levels.every((l) => l === "warning" || l === "error");
  }, "only warnings and errors");
  await screenshot(p, "dashboard-eventlog.png");
  assert.deepEqual(pageErrors, []);
});

test("billboard: its text; resources: buckets, info and a download of exactly the device's bytes", async () => {
  const b = await open(operator, "sign", "billboard");
  await waitFor(async () => (await b.getAttribute("data-ready")) === "true", "billboard read");
  assert.equal(await b.locator(".billboard-text").textContent(), misc.info.billboard);
  assert.equal(await b.locator(".billboard-name").textContent(), "cell_sign");

  const p = await open(operator, "store", "resource");
  await waitFor(async () => (await p.getAttribute("data-ready")) === "true", "buckets read");
  assert.deepEqual(await p.locator(".resource-bucket h4").allTextContents(), ["programs: robot programs", "empty: nothing yet"]);
  assert.deepEqual(await p.locator('[data-bucket="programs"] li code').allTextContents(), ["pick_place.txt", "calibration.yml"]);
  const item = p.locator('[data-bucket="programs"] li[data-key="pick_place.txt"]');
  await item.getByRole("button", { name: "Info" }).click();
  await waitFor(async () => (await item.locator(".resource-out").getAttribute("data-size")) === "3000", "info: 3000 bytes");
  assert.match(await item.locator(".resource-out").textContent(), /^2\.9 KiB, modified 2026-09-21T\d\d:\d\d:\d\dZ, pick_place\.txt \(3000 bytes\)$/);
  const [download] = await Promise.all([operator.waitForEvent("download", { timeout: 20000 }), item.getByRole("button", { name: "Download" }).click()]);
  assert.equal(download.suggestedFilename(), "pick_place.txt");
  const bytes = fs.readFileSync(await download.path());
  assert.equal(bytes.length, 3000);
  assert.equal(crypto.createHash("sha256").update(bytes).digest("hex"), misc.info.resources["pick_place.txt"]);
  await screenshot(p, "dashboard-resources.png");
  assert.deepEqual(pageErrors, []);
});

test("a viewer gets the live messages (the stored ones need the call right); a clock without time_utc and a log without getf_eventlog_messages fall back", async () => {
  const page = await loggedInPage(browser, gw.gateway.base, "bob", "log", pageErrors);
  const p = await open(page, "log", "eventlog");
  // reading the stored messages is a function call, which the viewer's role does not allow: said in place
  await waitFor(async () => /^messages: RobotRaconteur\.PermissionDenied/.test(await p.locator(".eventlog-error").textContent()), "the refusal shown", 30000);
  await waitFor(async () => Number(await p.getAttribute("data-messages")) >= 1, "live messages from the pipe", 30000);
  assert.match(await p.locator("tbody tr").first().locator("td").nth(4).textContent(), /^heartbeat \d+$/);
  for (const [device, name, member] of [["oldclock", "clock", "clock_info"], ["oldlog", "eventlog", "eventlog_info"]]) {
    const old = await open(page, device, name);
    assert.equal(await old.getAttribute("data-fallback"), "true", device);
    await page.locator(`.device-view[data-device="${device}"] .member[data-member="${member}"]`).first().waitFor({ timeout: 60000 });
  }
  await page.context().close();
  assert.deepEqual(pageErrors, []);
});

test("renderers: a JointTrajectory drawn per joint over time (a property and a function result), a PIDParam as one line", async () => {
  const page = operator;
  await page.goto(`${gw.gateway.base}/#/planner`);
  const card = (m) => page.locator(`.device-view[data-device="planner"] .member[data-member="${m}"]`).first();
  await card("last_plan").waitFor({ timeout: 60000 });
  await waitFor(async () => (await card("last_plan").locator("output.value").textContent()) === "3 joints, 11 waypoints over 2 s (shoulder, elbow, wrist)", "the trajectory's text", 30000);
  const figure = card("last_plan").locator("figure.frame-view canvas");
  await waitFor(async () => (await figure.count()) === 1 && (await figure.isVisible()), "the trajectory drawn");
  const drawn = await canvasPixels(figure);
  const colored = (px) => { let n = 0; for (let i = 0; i < px.data.length; i += 4) if (px.data[i] !== px.data[i + 1] || px.data[i + 1] !== px.data[i + 2]) n++; return n; };
  assert.ok(colored(drawn) > 300, `the joints' coloured lines: ${colored(drawn)} pixels`);
  // gains is a property of its own, read by its card apart from last_plan: wait for that read
  const gains = card("gains").locator("output.value");
  await waitFor(async () => Number(await gains.getAttribute("data-reads")) >= 1, "gains read", 30000);
  assert.equal(await gains.textContent(), "P 2.5, I 0.1, D 0.02; integral -5 … 5; command -10 … 10");
  // another trajectory (twice the swing over 4 s) drawn from a function's result: other pixels
  await card("plan").locator('input[aria-label="duration"]').fill("4");
  await card("plan").getByRole("button", { name: "Call" }).click();
  await waitFor(async () => /^3 joints, 11 waypoints over 4 s/.test(await card("plan").locator("output.result").textContent()), "plan()'s result", 20000);
  const result = card("plan").locator("figure.frame-view canvas");
  await waitFor(async () => (await result.count()) === 1 && (await result.isVisible()), "the result drawn");
  const other = await canvasPixels(result);
  assert.equal(other.width, drawn.width);
  assert.ok(pixelDiff(other.data, drawn.data).over > 300, "the other trajectory draws other pixels");
  await screenshot(card("last_plan"), "dashboard-trajectory.png");
  assert.deepEqual(pageErrors, []);
});
