// The dashboard on a service it has no special knowledge of: experimental.interop_test
// (test/interop/robdef/), served by rr_interop_service behind rr-gateway, in headless Chromium. Every
// writable property is read and written back from its editor (the service accepts only the exact
// value it served), and functions, generators, user errors, events, objrefs and pipes are used
// through the page. Screenshots go to $RR_ARTIFACTS.

import { test, before, after, afterEach } from "node:test";
import assert from "node:assert/strict";
import { spawn } from "node:child_process";
import readline from "node:readline";
import fs from "node:fs";
import path from "node:path";
import { settings, startGateway, launchChromium, apiDevices, waitFor } from "./harness.mjs";

const s = settings();
const interopService = process.env.RR_INTEROP_SERVICE;
let service, gateway, browser, page;
const pageErrors = [];

function card(member, within = page) {
  return within.locator(`.member[data-member="${member}"]`).first();
}

async function errorOf(c) {
  const e = c.locator(".member-error");
  return (await e.isHidden()) ? null : e.textContent();
}

async function call(c, args = {}) {
  const result = c.locator("output.result");
  const before = Number((await result.getAttribute("data-calls")) || 0);
  for (const [name, value] of Object.entries(args)) await c.locator(`[aria-label="${name}"]`).fill(String(value));
  await c.locator("button[type=submit]").click();
  await waitFor(async () => Number((await result.getAttribute("data-calls")) || 0) > before || (await errorOf(c)) !== null,
    "the call to finish");
  return { error: await errorOf(c), result: await result.textContent() };
}

before(async () => {
  assert.ok(s.gateway && interopService, "RR_GATEWAY and RR_INTEROP_SERVICE must be set");
  service = spawn(interopService, ["--port", "0", "--max-lifetime", "240"], { stdio: ["ignore", "pipe", "inherit"] });
  const info = await new Promise((resolve, reject) => {
    const t = setTimeout(() => reject(new Error("rr_interop_service not ready")), 30000);
    readline.createInterface({ input: service.stdout }).on("line", (line) => {
      try {
        const o = JSON.parse(line);
        if (o.url) { clearTimeout(t); resolve(o); }
      } catch { /* not the ready line */ }
    });
    service.on("exit", (code) => reject(new Error(`rr_interop_service exited with ${code}`)));
  });
  gateway = await startGateway({ ...s }, { interop: info.url });
  await waitFor(async () => (await apiDevices(gateway.base)).find((d) => d.name === "interop")?.state === "connected", "interop connected");
  browser = await launchChromium();
  page = await (await browser.newContext({ viewport: { width: 1366, height: 900 } })).newPage();
  page.on("pageerror", (e) => pageErrors.push(e));
  await page.goto(`${gateway.base}/#/interop`);
  await page.locator('.device-view[data-device="interop"] .badge').nth(1).filter({ hasText: "connected" }).waitFor({ timeout: 60000 });
});

after(async () => {
  if (page) {
    fs.mkdirSync(s.artifacts, { recursive: true });
    await page.screenshot({ path: path.join(s.artifacts, "20-interop.png"), fullPage: true }).catch(() => {});
  }
  await browser?.close();
  const status = gateway ? await gateway.child.stop() : null;
  if (service && service.exitCode === null) service.kill("SIGTERM");
  if (status) assert.equal(status.code, 0, `rr-gateway exited with ${JSON.stringify(status)}`);
});

afterEach(() => assert.deepEqual(pageErrors.splice(0).map(String), [], "uncaught errors in the page"));

test("every member of the root object has a card", async () => {
  const r = await (await fetch(`${gateway.base}/api/devices/interop`)).json();
  const names = r.members.map((m) => m.name).sort();
  const shown = (await page.locator(".object-panel > .member-section .member").evaluateAll(
    (els) => els.map((e) => e.dataset.member))).sort();
  assert.deepEqual(shown, names);
});

test("every writable property reads and writes back its own value", async () => {
  await call(card("reset"));
  const writable = await page.locator('.object-panel > .member-section[data-section="property"] .member')
    .evaluateAll((els) => els.filter((e) => e.querySelector(".editor") && !e.querySelector(".modifier")).map((e) => e.dataset.member));
  assert.ok(writable.length > 40, `${writable.length} writable properties`);
  const failed = [];
  for (const name of writable) {
    const c = card(name);
    await waitFor(async () => (await c.locator("output.value").textContent()) !== "" || (await errorOf(c)) !== null, `${name} read`);
    const readError = await errorOf(c);
    if (readError) { failed.push(`${name}: read: ${readError}`); continue; }
    const out = c.locator("output.value");
    const shown = await out.textContent();
    const reads = Number(await out.getAttribute("data-reads"));
    await c.locator(".editor button").click();
    await waitFor(async () => Number(await out.getAttribute("data-reads")) > reads || (await errorOf(c)) !== null, `${name} set`);
    const error = await errorOf(c);
    if (error) failed.push(`${name}: ${error}`);
    else if ((await out.textContent()) !== shown) failed.push(`${name}: ${shown} became ${await out.textContent()}`);
  }
  assert.deepEqual(failed, []);
});

test("an editor refuses a value that does not fit, before sending", async () => {
  const c = card("p_int16");
  await c.locator('[aria-label="p_int16 value"]').fill("40000");
  await c.locator(".editor button").click();
  await waitFor(async () => (await errorOf(c)) !== null, "error shown");
  assert.match(await errorOf(c), /out of range for int16/);
});

test("enum and bool editors", async () => {
  const e = card("p_enum");
  assert.equal(await e.locator("select").inputValue(), "blue");
  await e.locator("select").selectOption("minus");
  await e.locator(".editor button").click();
  await waitFor(async () => (await e.locator("output.value").textContent()) === "minus", "minus (-5) read back, shown by name");
  const b = card("p_bool");
  await b.locator('.editor input[type="checkbox"]').setChecked(false);
  await b.locator(".editor button").click();
  await waitFor(async () => (await b.locator("output.value").textContent()) === "false", "false read back");
  assert.equal(await errorOf(e), null);
  assert.equal(await errorOf(b), null);
});

test("functions: result, generator items, user error", async () => {
  assert.deepEqual(await call(card("add"), { a: 2, b: 40 }), { error: null, result: "42" });
  const gen = await call(card("count_up"), { start: 3, count: 4 });
  assert.equal(gen.error, null);
  assert.equal(gen.result, "1: 32: 43: 54: 6");
  const r = await call(card("throw_user"), { message: "boom" });
  assert.match(r.error, /experimental\.interop_test\.InteropError: boom/);
});

test("events go to the event log", async () => {
  assert.equal((await call(card("fire_events"), { count: 3 })).error, null);
  await waitFor(async () => (await page.locator('.event-log li[data-member="ev_values"]').count()) === 3, "3 ev_values");
  await page.locator('.event-log li[data-member="ev_empty"]').first().waitFor();
  assert.match(await page.locator('.event-log li[data-member="ev_values"]').first().textContent(), /id: /);
});

test("objrefs by name and pipes that echo", async () => {
  const byName = card("child_by_name");
  await byName.locator('[aria-label="child_by_name index"]').fill("alpha");
  await byName.locator("button[type=submit]").click();
  await page.locator('.child-object[data-path="child_by_name[alpha]"] .object-panel').waitFor();
  const pipe = card("p_echo");
  await pipe.locator("button", { hasText: "Connect" }).click();
  await pipe.locator('[aria-label="p_echo packet"]').fill('{"id": 7, "label": "seven", "values": [1.5, 2]}');
  await pipe.locator(".editor button").click();
  await waitFor(async () => Number(await pipe.locator(".stream").getAttribute("data-count")) >= 1, "the echo");
  assert.match(await pipe.locator(".stream output.value").textContent(), /id: 7, label: "seven", values: \[1\.5, 2\]/);
});

test("callbacks answered from the page", async () => {
  for (const [name, reply] of [["cb_compute", "2.5"], ["cb_notify", null]]) {
    const c = card(name);
    if (reply !== null) await c.locator(`[aria-label="${name} reply"]`).fill(reply);
    await c.locator("input[type=checkbox]").check();
  }
  assert.deepEqual(await call(card("call_callbacks"), { x: 1 }), { error: null, result: "3.5" });
  await page.locator('.event-log li[data-member="cb_compute"]', { hasText: "-> 2.5" }).first().waitFor();
  await page.locator('.event-log li[data-member="cb_notify"]').first().waitFor();
});

test("wires: out value echoed, write-only poke, stream plotted", async () => {
  const both = card("w_both");
  await both.locator('[aria-label="w_both out value"]').fill("1, 2, 3");
  await both.locator(".editor button").click();
  await waitFor(async () => (await both.locator(".stream output.value").textContent()) === "[3, 2, 1]", "the reversed echo");
  const sink = card("w_sink");
  await sink.locator('[aria-label="w_sink out value"]').fill("77");
  await sink.locator(".editor button").click();
  await waitFor(async () => (await call(card("w_sink_value"))).result === "77", "the service got 77");
  const state = card("w_state");
  await waitFor(async () => Number(await state.locator(".plot").getAttribute("data-samples")) >= 3, "w_state plotted");
});

test("memories: write and read back, pods as values", async () => {
  const mem = card("mem_double");
  await mem.locator('[aria-label="write start"]').fill("2");
  await mem.locator('[aria-label="values to write"]').fill("1.5, -2.25");
  await mem.locator("button", { hasText: "Write" }).click();
  await mem.locator('[aria-label="start"]').fill("2");
  await mem.locator('[aria-label="count"]').fill("2");
  await mem.locator("button", { hasText: "Read" }).click();
  await waitFor(async () => (await mem.locator(".memory-row .cells").first().textContent()) === "1.5 -2.25", "1.5 -2.25 read back");
  assert.equal(await errorOf(mem), null);
  const pods = card("mem_pod");
  await pods.locator('[aria-label="count"]').fill("1");
  await pods.locator("button", { hasText: "Read" }).click();
  await waitFor(async () => /^\{x: /.test(await pods.locator(".memory-row .cells").first().textContent()), "a pod shown");
});

test("a readonly pipe streams what the service sends", async () => {
  const pipe = card("p_stream");
  await pipe.locator("button", { hasText: "Connect" }).click();
  await waitFor(async () => (await pipe.getAttribute("data-open")) === "true", "connected");
  assert.equal((await call(card("send_stream"), { count: 5 })).error, null);
  await waitFor(async () => Number(await pipe.locator(".stream").getAttribute("data-count")) === 5, "5 packets");
  assert.equal(await pipe.locator(".stream output.value").textContent(), "[4, 2]");
  assert.equal(Number(await pipe.locator('.plot-readout [data-series="[0]"]').getAttribute("data-value")), 4);
});
