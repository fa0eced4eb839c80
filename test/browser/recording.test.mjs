// The dashboard's Record control and replay timeline (issue 44; web/src/record/, docs/recording.md
// "In the dashboard") in headless Chromium against rr-gateway with its demo devices:
// (1) the `create` device's packets wire, Bump event and DistanceTraveled property are recorded from
//     the page for a few seconds (live duration, size and message count shown and growing), stopped,
//     and the file is read by the reference reader (PyPI `mcap` in the venv): the channels of both
//     encodings and as many messages as the page said;
// (2) a recording into a sub-folder of the recordings root that cannot be created shows the gateway's
//     reason on the page and lists the recording as failed; a directory outside the root is refused;
// (3) a second gateway replays that file (`--replay create_replay=FILE`): the page shows a timeline
//     under the device; pause, seek, speed, loop and play from the page change what GET
//     api/replays/create_replay reports, and the page shows the values the gateway reports;
// (4) with logins (gateway.auth), a viewer (read only) sees the timeline with its controls disabled
//     and the gateway refuses its POST; an operator (write) gets the controls;
// (5) on the `webcam` device, members below the root typed into the control ("Below the root":
//     `Webcams[0].Name, Webcams[1].Name`) are recorded; a name that leads nowhere shows the refusal.
// Screenshots: docs/img/dashboard-recording.png and dashboard-replay.png with RR_DOCS_SCREENSHOTS=1.

import { test, before, after, afterEach } from "node:test";
import assert from "node:assert/strict";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";
import { spawnSync } from "node:child_process";
import { settings, startGateway, launchChromium, apiDevices, waitFor, writeOperatorViewerConfig } from "./harness.mjs";
import { screenshot } from "./std_support.mjs";

const s = settings();
let gateway, replayGateway, authGateway, browser, page, work, recordedFile, recordedMessages;
const pageErrors = [];

const view = (name) => page.locator(`.device-view[data-device="${name}"]`);
const card = (member) => page.locator(`.member[data-member="${member}"]`).first();
const control = () => view("create").locator(".record-control");
const timeline = () => view("create_replay").locator(".replay-timeline");

async function api(base, method, url, body) {
  const r = await fetch(`${base}/${url}`, { method, headers: { "Content-Type": "application/json" }, body: body && JSON.stringify(body) });
  return { status: r.status, body: await r.json() };
}

async function callFunction(c) {
  const result = c.locator("output.result");
  const before = Number((await result.getAttribute("data-calls")) || 0);
  await c.locator("button[type=submit]").click();
  await waitFor(async () => Number((await result.getAttribute("data-calls")) || 0) > before, "the call to finish");
}

async function openDevice(base, name) {
  await page.goto(`${base}/#/${name}`);
  await view(name).locator(".badge").nth(1).filter({ hasText: "connected" }).waitFor({ timeout: 60000 });
}

/**
 * The replay's pace from two status reads, judged without trusting any latency: each read is bracketed
 * by the test's clock (sent at a, answered at b), so at `speed` the position moved between
 * speed·(a2 − b1) and speed·(b2 − a1) seconds of the file. A pair counts only when it can tell `speed`
 * from speed 1 (the bracket's low end above what speed 1 could reach) and cannot hide a wrap (loop on:
 * both reads playing, the second ahead of the first and short of the end, less than a whole pass
 * between them). Other pairs are read again, the pause between the reads grown to outweigh the reads'
 * own latency, for up to 30 s. Returns {ok, text}.
 */
async function measurePace(status, durationS, speed = 2) {
  const tries = [];
  let gap = 0.3;  // s between the reads
  const deadline = Date.now() + 30000;
  while (Date.now() < deadline) {
    const a1 = performance.now() / 1000; const s1 = await status(); const b1 = performance.now() / 1000;
    await new Promise((r) => setTimeout(r, gap * 1000));
    const a2 = performance.now() / 1000; const s2 = await status(); const b2 = performance.now() / 1000;
    const moved = s2.position_s - s1.position_s;
    const low = speed * (a2 - b1), high = speed * (b2 - a1);
    const note = `moved ${moved.toFixed(3)} s of the file in ${(a2 - b1).toFixed(3)}..${(b2 - a1).toFixed(3)} s`;
    const clean = s1.state === "playing" && s2.state === "playing" && s1.speed === speed && s2.speed === speed
      && moved > 0 && s2.position_s < durationS && high < durationS;
    if (clean && (b2 - a1) < low - 0.01) {  // speed 1 could not have moved `low`: the pair decides
      return { ok: moved >= low - 0.005 && moved <= high + 0.005, text: `${note} (want ${low.toFixed(3)}..${high.toFixed(3)})` };
    }
    tries.push(clean ? `${note}: the reads took too long to tell the speed` : `${note}: wrapped or not playing`);
    const latency = (b1 - a1) + (b2 - a2);
    gap = Math.min(Math.max(0.3, 2 * latency + 0.1), 0.4 * durationS / speed);
  }
  return { ok: false, text: `no pair of reads could tell in 30 s: ${tries.slice(-5).join("; ")}` };
}

/** "m:ss.s" → seconds. */
const seconds = (text) => {
  const [m, sec] = text.trim().split(":");
  return Number(m) * 60 + Number(sec);
};

before(async () => {
  assert.ok(s.gateway, "RR_GATEWAY (path of rr-gateway) must be set");
  work = fs.mkdtempSync(path.join(os.tmpdir(), "rr-recui-"));
  // the recordings go below a root of the test's own; the page names sub-folders of it
  gateway = await startGateway(s, {}, 0, ["--no-discovery", "--recordings-root", path.join(work, "root")]);
  await waitFor(async () => (await apiDevices(gateway.base)).every((d) => d.state === "connected"), "the demo devices connected", 30000);
  browser = await launchChromium();
  page = await (await browser.newContext({ viewport: { width: 1366, height: 1000 } })).newPage();
  page.on("pageerror", (e) => pageErrors.push(e));
});

after(async () => {
  if (page) await screenshot(page, "recording-end.png", { docs: false, fullPage: true }).catch(() => {});
  await browser?.close();
  const statuses = [];
  for (const g of [gateway, replayGateway, authGateway]) if (g) statuses.push(await g.child.stop());
  if (work) fs.rmSync(work, { recursive: true, force: true });
  for (const st of statuses) assert.equal(st.code, 0, `rr-gateway exited with ${JSON.stringify(st)}`);
});

afterEach(() => {
  assert.deepEqual(pageErrors.splice(0).map(String), [], "uncaught errors in the page");
});

test("records the create device's members from the page; the file reads", async () => {
  await openDevice(gateway.base, "create");
  // the device streams its packets wire only while a client asked it to (and answers play_callback)
  const cb = card("play_callback");
  await cb.locator('[aria-label="play_callback reply"]').fill("60, 16");
  await cb.locator("input[type=checkbox]").check();
  await callFunction(card("StartStreaming"));

  const c = control();
  await c.locator("details.record-options summary").click();
  const boxes = c.locator('input[name="record-member"]');
  // defaults: wires, pipes and events checked, properties not
  assert.equal(await c.locator('input[value="packets"]').isChecked(), true);
  assert.equal(await c.locator('input[value="Bump"]').isChecked(), true);
  assert.equal(await c.locator('input[value="DistanceTraveled"]').isChecked(), false);
  assert.equal(await c.locator('input[value="Drive"]').count(), 0, "functions are not offered");
  await c.locator("button", { hasText: "none" }).click();
  assert.equal(await boxes.evaluateAll((bs) => bs.filter((b) => b.checked).length), 0);
  for (const m of ["packets", "Bump", "DistanceTraveled"]) await c.locator(`input[value="${m}"]`).check();
  await c.locator('select[name="record-encoding"]').selectOption("both");
  await c.locator('input[name="record-directory"]').fill("rec");

  await c.locator(".record-button").click();
  await c.locator('.record-button[data-action="stop"]').waitFor({ timeout: 60000 });
  assert.equal(await c.getAttribute("data-state"), "recording");
  // the live line grows: duration, size and messages
  const live = c.locator(".record-live");
  const facts = async () => {
    const t = await live.textContent();
    const m = t.match(/recording (\d+:\d+\.\d) · ([\d.]+ \w+) · (\d+) messages · (\d+) drops/);
    assert.ok(m, `live line "${t}"`);
    return { duration: seconds(m[1]), size: m[2], messages: Number(m[3]), drops: Number(m[4]) };
  };
  await waitFor(async () => (await facts()).messages > 0, "messages counted on the page", 20000);
  const first = await facts();
  await screenshot(view("create").locator(".device-tools"), "dashboard-recording.png");
  await waitFor(async () => (await facts()).duration >= first.duration + 2, "the duration grows on the page", 20000);
  const second = await facts();
  assert.ok(second.messages > first.messages, `messages grow: ${first.messages} → ${second.messages}`);
  assert.equal(second.drops, 0);

  await c.locator(".record-button").click();
  await c.locator('.record-button[data-action="record"]').waitFor({ timeout: 60000 });
  await callFunction(card("StopStreaming"));
  const item = c.locator(".recordings > li").first();
  await waitFor(async () => (await item.getAttribute("data-state")) === "stopped", "the recording listed as stopped", 20000);
  const files = await item.locator(".recording-files code").allTextContents();
  assert.equal(files.length, 1, `one file: ${files}`);
  recordedFile = path.resolve(files[0]);
  assert.ok(recordedFile.startsWith(path.join(work, "root", "rec") + path.sep), `${recordedFile} in the chosen sub-folder of the root`);
  assert.ok(fs.statSync(recordedFile).size > 0);
  const id = Number(await item.getAttribute("data-id"));
  const listed = (await api(gateway.base, "GET", "api/recordings")).body.recordings.find((r) => r.id === id);
  recordedMessages = listed.messages;
  assert.match(await item.locator(".recording-facts").textContent(), new RegExp(`· ${listed.messages} messages · 0 drops`));

  // the reference reader (PyPI mcap): channels of both encodings, and as many messages as listed
  const py = [
    "import sys, json, collections",
    "from mcap.reader import make_reader",
    "with open(sys.argv[1], 'rb') as f:",
    "    r = make_reader(f)",
    "    n = collections.Counter()",
    "    for schema, channel, message in r.iter_messages():",
    "        n[channel.topic + ' ' + channel.message_encoding] += 1",
    "print(json.dumps(n))",
  ].join("\n");
  const out = spawnSync(s.python, ["-c", py, recordedFile], { encoding: "utf8" });
  assert.equal(out.status, 0, out.stderr);
  const counts = JSON.parse(out.stdout);
  for (const topic of ["create/packets", "create/DistanceTraveled"]) {
    for (const enc of ["json", "robotraconteur"]) assert.ok(counts[`${topic} ${enc}`] > 0, `${topic} ${enc} messages: ${out.stdout}`);
  }
  assert.equal(Object.values(counts).reduce((a, b) => a + b, 0), recordedMessages, `messages in the file ${out.stdout}`);
});

test("a directory the gateway cannot create: the reason on the page, the recording failed", async () => {
  const c = control();
  // a file where the sub-folder's first part would go
  fs.mkdirSync(path.join(work, "root"), { recursive: true });
  fs.writeFileSync(path.join(work, "root", "blocked"), "");
  await c.locator('input[name="record-directory"]').fill("blocked/dir");
  await c.locator(".record-button").click();
  const error = c.locator(".record-error");
  await error.waitFor({ state: "visible", timeout: 60000 });
  assert.match(await error.textContent(), /blocked is not a folder/);
  const item = c.locator(".recordings > li").first();
  await waitFor(async () => (await item.getAttribute("data-state")) === "failed", "the recording listed as failed", 20000);
  assert.match(await item.locator(".recording-error").textContent(), /blocked is not a folder/);
  assert.equal(await c.locator(".record-button").textContent(), "Record", "nothing is recording");
  // outside the root: refused at once (400), not listed
  await c.locator('input[name="record-directory"]').fill("/tmp");
  await c.locator(".record-button").click();
  await waitFor(async () => /is an absolute path/.test(await error.textContent()), "the refusal on the page", 10000);
});

test("a replayed file: play, pause, seek, speed and loop from the timeline", async () => {
  assert.ok(recordedFile, "the recording of the first test");
  replayGateway = await startGateway(s, {}, 0, ["--no-demo", "--no-discovery", "--replay", `create_replay=${recordedFile}`]);
  const status = async () => (await api(replayGateway.base, "GET", "api/replays/create_replay")).body;
  await openDevice(replayGateway.base, "create_replay");
  const t = timeline();
  await t.waitFor({ timeout: 60000 });
  assert.equal(await view("create_replay").locator(".record-control").count(), 1, "a replayed device can be recorded too");
  // ... and its Record section says so (docs/recording.md "Recording a replay")
  const replayRecord = view("create_replay").locator(".record-control");
  await replayRecord.locator(".record-replay-note").waitFor({ timeout: 60000 });
  assert.equal(await replayRecord.locator("h3").textContent(), "Record this replay");
  assert.ok((await replayRecord.locator(".record-replay-note").textContent()).includes(recordedFile), "the note names the replayed file");
  assert.equal(await t.locator(".replay-file").textContent(), recordedFile);
  const st0 = await status();
  assert.ok(Math.abs(seconds(await t.locator(".replay-duration").textContent()) - st0.duration_s) <= 0.05, "the page shows the duration");
  assert.match(await t.locator(".replay-span").textContent(), /recorded \d{4}-\d\d-\d\dT.*Z – \d{4}-.*Z/);

  // loop on first: the short file then never ends while the test drives it
  await t.locator(".replay-loop").check();
  await waitFor(async () => (await status()).loop === true, "loop at the gateway");
  // playing (it may have ended before the page opened: Play starts it again), then pause
  if ((await t.locator(".replay-play").textContent()) === "Play") await t.locator(".replay-play").click();
  await waitFor(async () => (await status()).state === "playing", "playing at the gateway");
  await t.locator(".replay-play", { hasText: "Pause" }).waitFor();
  await t.locator(".replay-play").click();
  await waitFor(async () => (await status()).state === "paused", "paused at the gateway");
  await t.locator(".replay-play", { hasText: "Play" }).waitFor();
  const p1 = (await status()).position_s;
  await new Promise((r) => setTimeout(r, 700));
  assert.equal((await status()).position_s, p1, "the position stays while paused");

  // seek to the middle with the slider
  const target = Math.round(st0.duration_s * 500) / 1000;
  await t.locator(".replay-seek").evaluate((el, v) => {
    el.value = String(v);
    el.dispatchEvent(new Event("input", { bubbles: true }));
    el.dispatchEvent(new Event("change", { bubbles: true }));
  }, Math.round(target * 1000));
  await waitFor(async () => Math.abs((await status()).position_s - target) < 0.01, `the gateway at ${target} s`);
  await waitFor(async () => Math.abs(seconds(await t.locator(".replay-position").textContent()) - target) <= 0.05, "the page shows the position");
  assert.equal((await status()).state, "paused");
  const shownAtSeek = await t.locator(".replay-position").textContent();

  // speed
  await t.locator(".replay-speed").selectOption("2");
  await waitFor(async () => (await status()).speed === 2, "speed 2 at the gateway");
  await screenshot(view("create_replay").locator(".device-tools"), "dashboard-replay.png");

  // play: the position moves on at twice the recorded pace and the page follows
  await t.locator(".replay-play").click();
  await waitFor(async () => (await status()).state === "playing", "playing at the gateway");
  await waitFor(async () => (await status()).position_s !== target, "the position moves on", 20000);
  const pace = await measurePace(status, st0.duration_s);
  console.log(`# the replay's pace at speed 2: ${pace.text}`);
  assert.ok(pace.ok, `the replay's pace at speed 2: ${pace.text}`);
  await waitFor(async () => (await t.locator(".replay-position").textContent()) !== shownAtSeek, "the page's position moves");
  await t.locator(".replay-loop").uncheck();
  await waitFor(async () => (await status()).loop === false, "loop off at the gateway");
  // the replayed device's packets reach the page like a live device's
  await card("packets").locator(".plot-readout [data-series]").first().waitFor({ timeout: 60000 });
});

test("with logins: a viewer's timeline is read only, an operator's is not", async () => {
  assert.ok(recordedFile, "the recording of the first test");
  const config = writeOperatorViewerConfig(work, [
    "demo:",
    "  enabled: false",
    "devices:",
    "  - name: create_replay",
    `    replay: ${JSON.stringify(recordedFile)}`,
    "    paused: true",
  ]);
  authGateway = await startGateway(s, {}, 0, ["--config", config, "--no-discovery"]);
  const as = async (user, password) => {
    const context = await browser.newContext({ viewport: { width: 1366, height: 900 } });
    const p = await context.newPage();
    p.on("pageerror", (e) => pageErrors.push(e));
    await p.goto(`${authGateway.base}/#/create_replay`);
    await p.waitForURL(/\/login\.html/, { timeout: 20000 });
    await p.fill("#login-username", user);
    await p.fill("#login-password", password);
    await p.click("#login-submit");
    await p.waitForURL((u) => !u.pathname.endsWith("login.html"), { timeout: 20000 });
    const t = p.locator('.device-view[data-device="create_replay"] .replay-timeline');
    await t.waitFor({ timeout: 60000 });
    return { context, p, t };
  };
  const bob = await as("bob", "bob-pw");
  assert.equal(await bob.t.getAttribute("data-state"), "paused");
  for (const c of [".replay-play", ".replay-seek", ".replay-speed", ".replay-loop"]) {
    assert.equal(await bob.t.locator(c).isDisabled(), true, `${c} disabled for a viewer`);
  }
  assert.match(await bob.t.locator(".hint").textContent(), /needs write on the device/);
  const refused = await bob.p.evaluate(async () => (await fetch("api/replays/create_replay", { method: "POST", body: JSON.stringify({ state: "playing" }) })).status);
  assert.equal(refused, 403, "the gateway refuses a viewer's control");
  // recording needs write on the device too: a viewer's Record button is disabled, the gateway refuses
  const bobRecord = bob.p.locator('.device-view[data-device="create_replay"] .record-button');
  await bobRecord.waitFor({ timeout: 60000 });
  await bob.p.locator('.device-view[data-device="create_replay"] .record-refused').waitFor({ timeout: 60000 });
  assert.equal(await bobRecord.isDisabled(), true, "Record disabled for a viewer");
  const refusedRecording = await bob.p.evaluate(async () => (await fetch("api/recordings", { method: "POST", body: JSON.stringify({ device: "create_replay" }) })).status);
  assert.equal(refusedRecording, 403, "the gateway refuses a viewer's recording");
  await bob.context.close();

  const alice = await as("alice", "alice-pw");
  assert.equal(await alice.t.locator(".replay-play").isDisabled(), false, "an operator may control the replay");
  assert.equal(await alice.t.locator(".hint").count(), 0);
  await alice.t.locator(".replay-play").click();
  await alice.t.locator(".replay-play", { hasText: "Pause" }).waitFor({ timeout: 60000 });
  assert.equal(await alice.p.locator('.device-view[data-device="create_replay"] .record-button').isDisabled(), false, "an operator may record");
  assert.equal(await alice.p.locator(".record-refused").count(), 0);
  await alice.context.close();
});

test("members below the root object typed into the Record control (the webcam's cameras)", async () => {
  await openDevice(gateway.base, "webcam");
  const c = view("webcam").locator(".record-control");
  await c.locator("details.record-options summary").click();
  await c.locator("button", { hasText: "none" }).click();
  const paths = c.locator('input[name="record-paths"]');
  assert.match(await paths.getAttribute("placeholder"), /Webcams\[0\]\./, "the hint names the device's objref");
  // a name that leads nowhere: the gateway's reason on the page, nothing recorded
  await paths.fill("Webcams.Name");
  await c.locator(".record-button").click();
  await waitFor(async () => /needs an index/.test(await c.locator(".record-error").textContent()), "the refusal on the page", 20000);
  assert.equal(await c.locator(".record-button").textContent(), "Record");
  await paths.fill("Webcams[0].Name, Webcams[1].Name");
  await c.locator('input[name="record-directory"]').fill("sub");
  await c.locator(".record-button").click();
  await c.locator('.record-button[data-action="stop"]').waitFor({ timeout: 60000 });
  await waitFor(async () => /[1-9]\d* messages/.test(await c.locator(".record-live").textContent()), "the cameras' names recorded", 15000);
  await c.locator(".record-button").click();
  await c.locator('.record-button[data-action="record"]').waitFor({ timeout: 60000 });
  const item = c.locator(".recordings > li").first();
  await waitFor(async () => (await item.getAttribute("data-state")) === "stopped", "the recording listed as stopped", 20000);
  const id = Number(await item.getAttribute("data-id"));
  const listed = (await api(gateway.base, "GET", "api/recordings")).body.recordings.find((r) => r.id === id);
  assert.deepEqual(listed.members, ["Webcams[0].Name", "Webcams[1].Name"]);
  assert.ok(listed.messages >= 2, `${listed.messages} messages`);
});
