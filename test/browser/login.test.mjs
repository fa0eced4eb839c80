// The gateway's own logins in headless Chromium (gateway.auth, docs/security.md "Gateway users and
// permissions"): a gateway with users from an official password file and two roles (operator: all;
// viewer: read only). Without a session the dashboard lands on login.html; a wrong password shows the
// error and stays; the right one opens the dashboard with the user's name and live device data; a
// viewer's write is refused (HTTP 403 PermissionDenied); "Log out" returns to the login page and the
// old cookie no longer works; a page of another origin on the same host (same site, so the session
// cookie goes with its requests) gets neither WebSocket nor readable API answers.

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import fs from "node:fs";
import http from "node:http";
import net from "node:net";
import os from "node:os";
import path from "node:path";
import { settings, writeOperatorViewerConfig, startGateway, launchChromium, waitFor } from "./harness.mjs";

const s = settings();
let tmp, gateway, browser, base;

before(async () => {
  tmp = fs.mkdtempSync(path.join(os.tmpdir(), "rr-web-login-"));
  const config = writeOperatorViewerConfig(tmp, [
    "demo:",
    "  enabled: true",
  ]);
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
  await page.locator('#device-list li[data-device="create"][data-state="connected"]').waitFor({ timeout: 60000 });
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
  await error.waitFor({ state: "visible", timeout: 60000 });
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
  await page.locator("#user-name").waitFor({ timeout: 60000 });
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
  await page.locator("#user-name").waitFor({ timeout: 60000 });
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
  await refusal.waitFor({ state: "visible", timeout: 60000 });
  assert.match(await refusal.textContent(), /PermissionDenied|may not call/i);
  await page.screenshot({ path: path.join(s.artifacts, "51-login-viewer.png") });
  await context.close();
});

/** A TCP relay to the gateway that keeps what each connection sent and got: it shows that the browser
 * did send the session cookie and what the gateway answered, which a page cannot see cross-origin. */
async function tap(port) {
  const conns = [];
  const sockets = new Set();
  const server = net.createServer((client) => {
    const c = { sent: "", got: "" };
    conns.push(c);
    const upstream = net.connect(port, "127.0.0.1");
    for (const s of [client, upstream]) {
      sockets.add(s);
      s.on("close", () => sockets.delete(s));
    }
    client.on("data", (d) => { c.sent += d.toString("latin1"); upstream.write(d); });
    upstream.on("data", (d) => { c.got += d.toString("latin1"); client.write(d); });
    for (const [a, b] of [[client, upstream], [upstream, client]]) {
      a.on("end", () => b.end());
      a.on("error", () => b.destroy());
    }
  });
  await new Promise((r) => server.listen(0, "127.0.0.1", r));
  const close = () => {
    server.close();
    for (const s of sockets) s.destroy();
  };
  return { port: server.address().port, conns, close };
}

/** The HTTP/1.1 messages (head and body, by Content-Length) one side of a connection sent, in order. */
function httpMessages(text) {
  const out = [];
  let at = 0;
  while (at < text.length) {
    const end = text.indexOf("\r\n\r\n", at);
    if (end < 0) break;
    const head = text.slice(at, end);
    const length = Number(/^content-length: *(\d+)/im.exec(head)?.[1] ?? 0);
    out.push(text.slice(at, end + 4 + length));
    at = end + 4 + length;
  }
  return out;
}

test("a page of another origin on the same host cannot use the logged-in session (WebSocket, fetch)", async () => {
  const context = await browser.newContext();
  const page = await context.newPage();
  await logIn(page, "alice", "alice-pw");
  await page.waitForURL((u) => !u.pathname.endsWith("login.html"), { timeout: 20000 });
  const cookie = (await context.cookies()).find((c) => c.name === "rrgw_session");
  assert.ok(cookie, "no session cookie");
  // http://127.0.0.1:OTHER is another origin but the same site as the gateway (ports do not count for
  // SameSite), so the Strict cookie goes with its requests: only the Origin check stands in the way.
  const other = http.createServer((req, res) => {
    res.writeHead(200, { "Content-Type": "text/html" });
    res.end("<!doctype html><title>another origin</title>");
  });
  await new Promise((r) => other.listen(0, "127.0.0.1", r));
  const origin = `http://127.0.0.1:${other.address().port}`;
  const relay = await tap(gateway.port);
  try {
    // The relay is transparent: the cookie it carries is alice's live session.
    const viaRelay = await fetch(`http://127.0.0.1:${relay.port}/api/whoami`, { headers: { Cookie: `rrgw_session=${cookie.value}` } });
    assert.equal(viaRelay.status, 200);
    assert.equal((await viaRelay.json()).user, "alice");

    const attacker = await context.newPage();
    await attacker.goto(`${origin}/`);
    const attempt = (port) => attacker.evaluate(async (port) => {
      const socket = (protocol) => new Promise((resolve) => {
        const r = { protocol, opened: false, messages: 0 };
        const w = new WebSocket(`ws://127.0.0.1:${port}/?service=create`, protocol);
        w.onopen = () => { r.opened = true; };
        w.onmessage = () => { r.messages++; };
        w.onclose = () => resolve(r);
        setTimeout(() => { r.timedOut = true; w.close(); resolve(r); }, 10000);
      });
      const sockets = [await socket("rr-gateway.json.v1"), await socket("robotraconteur.robotraconteur.com")];
      const read = async (init) => {
        try {
          const res = await fetch(`http://127.0.0.1:${port}/api/devices`, { credentials: "include", ...init });
          return { type: res.type, status: res.status, body: await res.text() };
        } catch (e) {
          return { refused: String(e) };
        }
      };
      const cors = await read({});
      const noCors = await read({ mode: "no-cors" });
      // A cross-site state change (a form-like POST) with the cookie: the browser sends it and an Origin.
      let post;
      try {
        post = (await fetch(`http://127.0.0.1:${port}/api/devices/create/functions/Drive`, {
          method: "POST", mode: "no-cors", credentials: "include", headers: { "Content-Type": "text/plain" },
          body: JSON.stringify({ args: [0, 0] }),
        })).type;
      } catch (e) {
        post = String(e);
      }
      return { sockets, cors, noCors, post };
    }, port);

    for (const port of [gateway.port, relay.port]) {
      const r = await attempt(port);
      for (const w of r.sockets)
        assert.deepEqual(w, { protocol: w.protocol, opened: false, messages: 0 }, `port ${port}: ${JSON.stringify(w)}`);
      assert.ok(r.cors.refused, `port ${port}: a credentialed cross-origin fetch was readable: ${JSON.stringify(r.cors)}`);
      // no-cors: an opaque answer, nothing of it readable by the page
      assert.deepEqual(r.noCors, { type: "opaque", status: 0, body: "" }, `port ${port}`);
      assert.equal(r.post, "opaque", `port ${port}`);
    }
    // What went over the relay: every request of the page carried alice's cookie, and the gateway
    // refused every one that named the foreign Origin with 403 before looking at the cookie (a no-cors
    // GET carries no Origin; its answer stays opaque to the page, checked above).
    const exchanges = relay.conns.flatMap((c) => {
      const reqs = httpMessages(c.sent);
      const answers = httpMessages(c.got);
      return reqs.map((head, i) => ({ head, answer: answers[i] ?? "" }));
    }).filter((x) => /^user-agent: .*Chrom/im.test(x.head));
    const refused = new Set();
    for (const { head, answer } of exchanges) {
      assert.ok(head.includes(`rrgw_session=${cookie.value}`), `the browser did not send the cookie:\n${head}`);
      if (!/^origin: /im.test(head)) continue;
      assert.match(head, new RegExp(`^origin: ${origin}\r?$`, "im"));
      assert.match(answer, /^HTTP\/1\.1 403 [^]*Forbidden Origin/, `the gateway's answer to\n${head}\n---\n${answer.slice(0, 300)}`);
      const proto = /^sec-websocket-protocol: (.*)$/im.exec(head);
      refused.add(proto ? proto[1].trim() : head.split(" ").slice(0, 2).join(" "));
    }
    for (const k of ["rr-gateway.json.v1", "robotraconteur.robotraconteur.com", "GET /api/devices",
      "POST /api/devices/create/functions/Drive"])
      assert.ok(refused.has(k), `no refused ${k} through the relay: ${[...refused]}`);
    await attacker.close();
  } finally {
    relay.close();
    other.close();
    await context.close();
  }
});
