// The gateway's own logins in headless Chromium (gateway.auth, docs/security.md "Gateway users and
// permissions"): a gateway with users from an official password file and two roles (operator: all;
// viewer: read only). Without a session the dashboard lands on login.html; a wrong password shows the
// error and stays; the right one opens the dashboard with the user's name and live device data; a
// viewer's write is refused (HTTP 403 PermissionDenied); "Log out" returns to the login page and the
// old cookie no longer works.

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import crypto from "node:crypto";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";
import { settings, startGateway, launchChromium, waitFor } from "./harness.mjs";

const s = settings();
const md5 = (t) => crypto.createHash("md5").update(t).digest("hex");
let tmp, gateway, browser, base;

before(async () => {
  tmp = fs.mkdtempSync(path.join(os.tmpdir(), "rr-web-login-"));
  const users = path.join(tmp, "users.txt");
  fs.writeFileSync(users, `alice ${md5("alice-pw")} operator,objectlock\nbob ${md5("bob-pw")} viewer\n`, { mode: 0o600 });
  const config = path.join(tmp, "gateway.yaml");
  fs.writeFileSync(config, [
    "gateway:",
    "  auth:",
    `    users: ${users}`,
    "    roles:",
    "      operator:",
    "        - allow: [read, write, call]",
    "      viewer:",
    "        - devices: \"*\"",
    "          members: \"*\"",
    "          allow: [read]",
    "demo:",
    "  enabled: true",
    "",
  ].join("\n"));
  gateway = await startGateway(s, {}, 0, ["--config", config]);
  base = gateway.base;
  browser = await launchChromium();
});

after(async () => {
  await browser?.close();
  if (gateway) await gateway.child.stop();
  if (tmp) fs.rmSync(tmp, { recursive: true, force: true });
});

async function logIn(page, user, password) {
  await page.goto(`${base}/#/create`);
  await page.waitForURL(/\/login\.html/, { timeout: 20000 });
  await page.fill("#login-username", user);
  await page.fill("#login-password", password);
  await page.click("#login-submit");
}

async function liveData(page) {
  await page.locator('#device-list li[data-device="create"][data-state="connected"]').waitFor({ timeout: 20000 });
  const dist = page.locator('.member[data-member="DistanceTraveled"]');
  const samples = async () => Number(await dist.locator(".plot").getAttribute("data-samples"));
  const n = await waitFor(samples, "distance samples", 30000);
  await waitFor(async () => (await samples()) > n + 3, "the property polled over the logged-in rr+ws session", 30000);
}

test("no session: login page; wrong password: error; right one: dashboard; log out: cookie dead", async () => {
  // The API itself without a cookie: 401.
  assert.equal((await fetch(`${base}/api/devices`)).status, 401);
  const context = await browser.newContext({ viewport: { width: 1366, height: 900 } });
  const page = await context.newPage();
  const errors = [];
  page.on("pageerror", (e) => errors.push(String(e)));

  await logIn(page, "alice", "not-her-password");
  const error = page.locator("#login-error");
  await error.waitFor({ state: "visible", timeout: 10000 });
  assert.match(await error.textContent(), /invalid username or password/i);
  assert.match(page.url(), /\/login\.html/);
  assert.equal((await context.cookies()).filter((c) => c.name === "rrgw_session").length, 0);

  await page.fill("#login-password", "alice-pw");
  await page.click("#login-submit");
  await page.waitForURL((u) => !u.pathname.endsWith("login.html"), { timeout: 20000 });
  const cookie = (await context.cookies()).find((c) => c.name === "rrgw_session");
  assert.ok(cookie, "no session cookie");
  assert.equal(cookie.httpOnly, true);
  assert.equal(cookie.sameSite, "Strict");
  await page.goto(`${base}/#/create`);
  await page.locator("#user-name").waitFor({ timeout: 20000 });
  assert.equal(await page.locator("#user-name").textContent(), "alice");
  await liveData(page);
  const me = await page.evaluate(async () => (await fetch("api/whoami")).json());
  assert.equal(me.user, "alice");
  // The operator may call what the viewer below may not (the same request, so the 403 there is the role).
  const drive = await page.evaluate(async () => (await fetch("api/devices/create/functions/Drive", {
    method: "POST", headers: { "Content-Type": "application/json" }, body: JSON.stringify({ args: [0, 0] }),
  })).status);
  assert.equal(drive, 200);
  fs.mkdirSync(s.artifacts, { recursive: true });
  await page.screenshot({ path: path.join(s.artifacts, "50-login-alice.png") });

  // Log out: back on the login page, and the old cookie is refused.
  await page.click("#logout");
  await page.waitForURL(/\/login\.html/, { timeout: 20000 });
  const r = await fetch(`${base}/api/devices`, { headers: { Cookie: `rrgw_session=${cookie.value}` } });
  assert.equal(r.status, 401);
  await page.goto(`${base}/`);
  await page.waitForURL(/\/login\.html/, { timeout: 20000 });
  assert.deepEqual(errors, []);
  await context.close();
});

test("a viewer sees live data but cannot write", async () => {
  const context = await browser.newContext({ viewport: { width: 1366, height: 900 } });
  const page = await context.newPage();
  await logIn(page, "bob", "bob-pw");
  await page.waitForURL((u) => !u.pathname.endsWith("login.html"), { timeout: 20000 });
  await page.goto(`${base}/#/create`);
  await page.locator("#user-name").waitFor({ timeout: 20000 });
  assert.equal(await page.locator("#user-name").textContent(), "bob");
  await liveData(page);
  // Reading is allowed, calling a function (driving the robot) is not: 403 PermissionDenied.
  const read = await page.evaluate(async () => (await fetch("api/devices/create/properties/DistanceTraveled")).status);
  assert.equal(read, 200);
  const call = await page.evaluate(async () => {
    const r = await fetch("api/devices/create/functions/Drive", {
      method: "POST", headers: { "Content-Type": "application/json" },
      body: JSON.stringify({ args: [0, 0] }),
    });
    return { status: r.status, body: await r.json().catch(() => null) };
  });
  assert.equal(call.status, 403, JSON.stringify(call));
  assert.equal(call.body?.error?.name, "RobotRaconteur.PermissionDenied");
  // The dashboard shows the refusal where it happens: Drive through the page's RR session.
  const drive = page.locator('.device-view[data-device="create"] .member[data-member="Drive"]');
  await drive.locator('[aria-label="velocity"]').fill("0");
  await drive.locator('[aria-label="radius"]').fill("32767");
  await drive.locator("button[type=submit]").click();
  const refusal = drive.locator(".member-error");
  await refusal.waitFor({ state: "visible", timeout: 15000 });
  assert.match(await refusal.textContent(), /PermissionDenied|may not call/i);
  await page.screenshot({ path: path.join(s.artifacts, "51-login-viewer.png") });
  await context.close();
});
