// A device's own logins in the dashboard (docs/security.md "Logins and locks through the gateway"):
// rr_interop_service with users from an official password file, behind rr-gateway as an `auth:
// passthrough` device, in headless Chromium. The device refuses the page's session without a login,
// so the device view shows a login form with the device's error (no reconnect loop); a wrong password
// shows the device's error again; the right one shows the members, read on the user's own upstream
// session. A user lock taken through the gateway by an official Python client shows on the device's
// card with its holder; under alice's lock the page logged in as alice still reads while the page
// logged in as bob (after "Log out of device") gets the device's ObjectLockedError. A second service
// without logins opens as before, with no form. Screenshots go to $RR_ARTIFACTS.

import { test, before, after, afterEach } from "node:test";
import assert from "node:assert/strict";
import { spawn } from "node:child_process";
import crypto from "node:crypto";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";
import readline from "node:readline";
import { ROOT, settings, startGateway, launchChromium, apiDevices, waitFor } from "./harness.mjs";

const s = settings();
const interopService = process.env.RR_INTEROP_SERVICE;
const md5 = (t) => crypto.createHash("md5").update(t).digest("hex");
const USERS = { alice: ["alice-pw", "objectlock"], bob: ["bob-pw", "objectlock"], gateway: ["gateway-pw", "_"] };
let tmp, secured, plain, gateway, browser, context, page, locker;
const pageErrors = [];

function readyLine(line, key) {
  if (line.trim() === key) return {};
  try {
    const o = JSON.parse(line);
    return o && typeof o === "object" && key in o ? o : null;
  } catch {
    return null; // not the ready line
  }
}

/** Starts `cmd`; resolves with the process and its first stdout line that is `key` or JSON holding `key`. */
function startWithJsonLine(name, cmd, args, key, timeoutMs = 30000) {
  const proc = spawn(cmd, args, { stdio: ["pipe", "pipe", "pipe"] });
  const stderr = [];
  proc.stderr.on("data", (d) => {
    stderr.push(String(d));
    if (process.env.RR_BROWSER_VERBOSE) process.stderr.write(`[${name}] ${d}`);
  });
  return new Promise((resolve, reject) => {
    const t = setTimeout(() => reject(new Error(`${name}: no "${key}" line within ${timeoutMs} ms\n${stderr.join("")}`)), timeoutMs);
    readline.createInterface({ input: proc.stdout }).on("line", (line) => {
      const o = readyLine(line, key);
      if (o) {
        clearTimeout(t);
        resolve({ proc, info: o });
      }
    });
    proc.on("exit", (code) => { clearTimeout(t); reject(new Error(`${name} exited with ${code}\n${stderr.join("")}`)); });
  });
}

async function stopProc(proc) {
  if (!proc || proc.exitCode !== null || proc.signalCode !== null) return;
  const exited = new Promise((resolve) => proc.on("exit", resolve));
  proc.kill("SIGTERM");
  const t = setTimeout(() => proc.kill("SIGKILL"), 20000);
  await exited;
  clearTimeout(t);
}

const view = (device) => page.locator(`.device-view[data-device="${device}"]`);
const form = () => view("interop").locator("form.device-login");
const formError = () => form().locator(".device-login-error");
const sessionBadge = (device) => view(device).locator(".device-header .badge").nth(1);
const card = (device, member) => view(device).locator(`.member[data-member="${member}"]`).first();
const lockLines = () => page.locator('#device-list li[data-device="interop"] .device-lock');
const device = async (name) => (await apiDevices(gateway.base)).find((d) => d.name === name);

/** A screenshot of the viewport (the interop service's full page is metres long). */
async function shot(name) {
  fs.mkdirSync(s.artifacts, { recursive: true });
  await page.screenshot({ path: path.join(s.artifacts, name) });
}

async function logIn(user, password) {
  await form().locator('input[name="username"]').fill(user);
  await form().locator('input[name="password"]').fill(password);
  await form().locator("button.device-login-submit").click();
}

/** Clicks Read on a property's card; resolves with its value text or its error. */
async function read(device, member) {
  const c = card(device, member);
  const out = c.locator("output.value");
  const error = c.locator(".member-error");
  const count = async (loc, attr) => Number((await loc.getAttribute(attr)) || 0);
  // The previous read's error may still be on the card: wait for this read's own outcome.
  const reads = await count(out, "data-reads");
  const errors = await count(error, "data-shown");
  await c.locator("button", { hasText: /^Read$/ }).click();
  await waitFor(async () => (await count(out, "data-reads")) > reads || (await count(error, "data-shown")) > errors,
    `${member} read`);
  return (await count(error, "data-shown")) > errors && !(await error.isHidden())
    ? { error: await error.textContent() } : { value: await out.textContent() };
}

before(async () => {
  assert.ok(s.gateway && interopService, "RR_GATEWAY and RR_INTEROP_SERVICE must be set");
  tmp = fs.mkdtempSync(path.join(os.tmpdir(), "rr-web-device-login-"));
  const users = path.join(tmp, "users.txt");
  fs.writeFileSync(users, "# official password file format: user md5(password) privileges\n" +
    Object.entries(USERS).map(([u, [pw, priv]]) => `${u} ${md5(pw)} ${priv}\n`).join(""), { mode: 0o600 });
  secured = await startWithJsonLine("rr_interop_service --users", interopService,
    ["--port", "0", "--max-lifetime", "240", "--users", users], "url");
  plain = await startWithJsonLine("rr_interop_service", interopService, ["--port", "0", "--max-lifetime", "240"], "url");
  const config = path.join(tmp, "gateway.yaml");
  fs.writeFileSync(config, [
    "demo:",
    "  enabled: false",
    "devices:",
    "  - name: interop",
    `    url: ${JSON.stringify(secured.info.url)}`,
    "    username: gateway",
    "    password: gateway-pw",
    "    auth: passthrough",
    "  - name: plain",
    `    url: ${JSON.stringify(plain.info.url)}`,
    "",
  ].join("\n"));
  gateway = await startGateway(s, {}, 0, ["--config", config]);
  await waitFor(async () => (await apiDevices(gateway.base)).every((d) => d.state === "connected"), "both devices connected");
  browser = await launchChromium();
  context = await browser.newContext({ viewport: { width: 1366, height: 900 } });
  page = await context.newPage();
  page.on("pageerror", (e) => pageErrors.push(e));
});

after(async () => {
  if (page) await shot("63-device-login-end.png").catch(() => {});
  await browser?.close();
  await stopProc(locker?.proc);
  const status = gateway ? await gateway.child.stop() : null;
  await stopProc(secured?.proc);
  await stopProc(plain?.proc);
  if (tmp) fs.rmSync(tmp, { recursive: true, force: true });
  if (status) assert.equal(status.code, 0, `rr-gateway exited with ${JSON.stringify(status)}`);
});

afterEach(() => assert.deepEqual(pageErrors.splice(0).map(String), [], "uncaught errors in the page"));

test("the device refuses the page without a login: the form shows the device's error and nothing retries", async () => {
  await page.goto(`${gateway.base}/#/interop`);
  await form().waitFor({ state: "visible", timeout: 60000 });
  await formError().waitFor({ state: "visible" });
  assert.match(await formError().textContent(), /^RobotRaconteur\.AuthenticationError: /);
  assert.equal(await sessionBadge("interop").textContent(), "login required");
  assert.equal(await view("interop").locator(".member").count(), 0);
  await shot("60-device-login-form.png");
  // No reconnect loop: the gateway sees no new attempts while the form waits.
  const log = view("interop").locator(".event-log li");
  const entries = await log.count();
  await new Promise((r) => setTimeout(r, 2500));
  assert.equal(await log.count(), entries, "no further connect attempts while the form waits");
  assert.equal(await sessionBadge("interop").textContent(), "login required");
});

test("a wrong password shows the device's error again in the form", async () => {
  await logIn("alice", "not-her-password");
  await waitFor(async () => /Invalid username or password/i.test(await formError().textContent()) && await formError().isVisible(),
    "the device's refusal of the wrong password");
  assert.match(await formError().textContent(), /^RobotRaconteur\.AuthenticationError: .*Invalid username or password/i);
  assert.equal(await view("interop").locator(".member").count(), 0);
  assert.equal(await form().locator('input[name="username"]').inputValue(), "alice");
  await shot("61-device-login-wrong.png");
});

test("the right password: the device's members, a property read on the user's own upstream session", async () => {
  await logIn("alice", USERS.alice[0]);
  await form().waitFor({ state: "hidden", timeout: 60000 });
  await sessionBadge("interop").filter({ hasText: "connected" }).waitFor({ timeout: 60000 });
  assert.equal(await view("interop").locator(".device-user-name").textContent(), "alice");
  const baseName = card("interop", "base_name").locator("output.value");
  await waitFor(async () => (await baseName.textContent()) === '"interop root"', "base_name read through the session");
  assert.ok((await view("interop").locator(".member").count()) > 40, "the device's members are shown");
  // Only the page's session goes upstream as a passthrough session (the gateway's own is apart).
  assert.equal((await device("interop")).passthrough_sessions, 1);
  // The credentials stay in the page's memory.
  assert.deepEqual(await page.evaluate(() => [localStorage.length, sessionStorage.length, document.cookie]), [0, 0, ""]);
  assert.deepEqual(await context.cookies(), []);
});

test("a lock taken through the gateway shows its holder on the card; the locking user's page still reads", async () => {
  const url = `rr+tcp://127.0.0.1:${gateway.port}/?service=interop`;
  // An official Python client of alice's takes a user lock on the root object through the gateway.
  locker = await startWithJsonLine("official client (locker)", s.python,
    [path.join(ROOT, "test/interop/locks_logins.py"), "--child-lock", url, "alice", USERS.alice[0]], "locked");
  await waitFor(async () => (await lockLines().count()) === 1, "the lock on the device's card");
  assert.equal(await lockLines().first().textContent(), "user lock on interop by alice");
  assert.equal(await lockLines().first().getAttribute("data-kind"), "user");
  await shot("62-device-login-lock.png");
  // A user lock admits the user's other sessions: the page logged in as alice reads (the gateway's
  // own session would get ObjectLockedError).
  assert.deepEqual(await read("interop", "base_name"), { value: '"interop root"' });
});

test("log out of the device: the form again; logged in as bob the page gets the device's lock error", async () => {
  await view("interop").locator("button.device-logout").click();
  await form().waitFor({ state: "visible", timeout: 60000 });
  assert.equal(await formError().isHidden(), true);
  assert.equal(await view("interop").locator(".member").count(), 0);
  assert.equal(await view("interop").locator(".device-user").isHidden(), true);
  await waitFor(async () => (await device("interop")).passthrough_sessions === 1, "the page's upstream session closed (the locker's stays)");
  await logIn("bob", USERS.bob[0]);
  await sessionBadge("interop").filter({ hasText: "connected" }).waitFor({ timeout: 60000 });
  assert.equal(await view("interop").locator(".device-user-name").textContent(), "bob");
  const r = await read("interop", "base_name");
  assert.match(r.error ?? "", /ObjectLockedError.*alice/, JSON.stringify(r));
  // The lock goes with the locking client's process; the card follows.
  await stopProc(locker.proc);
  await waitFor(async () => (await lockLines().count()) === 0, "the lock gone from the card");
  assert.deepEqual(await read("interop", "base_name"), { value: '"interop root"' });
});

test("a device without logins opens as before: no form", async () => {
  await page.goto(`${gateway.base}/#/plain`);
  await sessionBadge("plain").filter({ hasText: "connected" }).waitFor({ timeout: 60000 });
  await waitFor(async () => (await card("plain", "base_name").locator("output.value").textContent()) === '"interop root"', "plain base_name");
  assert.equal(await view("plain").locator("form.device-login").isHidden(), true);
  assert.equal(await view("plain").locator(".device-user").isHidden(), true);
  // Back to the device with logins: this page still holds bob's login (in memory), no form.
  await page.goto(`${gateway.base}/#/interop`);
  await sessionBadge("interop").filter({ hasText: "connected" }).waitFor({ timeout: 60000 });
  assert.equal(await view("interop").locator(".device-user-name").textContent(), "bob");
  assert.equal(await form().isHidden(), true);
});
