// The gateway under a path prefix behind nginx with TLS (gateway-config/nginx-rr-gateway-prefix.conf,
// the file docs/deployment.md ships): the site keeps / for itself, the gateway lives at /rr/. In
// headless Chromium the dashboard at https://site.example.org:PORT/rr/ lists the devices (JSON API),
// opens a device view whose RR session goes to rr+wss://…/rr/ (the wasm client package) and shows
// live data; the JSON WebSocket API answers under /rr/ too. The gateway trusts nginx's
// X-Forwarded-For/-Proto (nginx connects from 127.0.0.2 with proxy_bind, the trusted proxy given with
// --trusted-proxy) and not the same headers from anyone else. Skipped when nginx or openssl is missing.

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import fs from "node:fs";
import https from "node:https";
import os from "node:os";
import path from "node:path";
import { settings, startGateway, waitFor, CHROMIUM_ARGS, webRequire } from "./harness.mjs";
import { NGINX, HAVE_OPENSSL, freePort, selfSignedCert, startNginx } from "./nginx_common.mjs";

const s = settings();
const SKIP = !NGINX || !HAVE_OPENSSL ? "nginx or openssl not installed (./scripts/setup.sh installs them)" : false;
const HOST = "site.example.org";
let tmp, gateway, nginx, browser, site;

before(async () => {
  if (SKIP) return;
  tmp = fs.mkdtempSync(path.join(os.tmpdir(), "rr-web-prefix-"));
  fs.chmodSync(tmp, 0o755); // nginx workers (unprivileged) use the temp folders
  const httpsPort = await freePort();
  site = `https://${HOST}:${httpsPort}`;
  gateway = await startGateway({ ...s }, {}, 0, ["--log-level", "info", "--trusted-proxy", "127.0.0.2"]);
  const { cert, key } = selfSignedCert(tmp, HOST);
  nginx = await startNginx(tmp, "nginx-rr-gateway-prefix.conf", [
    ["server 127.0.0.1:8080;", `server 127.0.0.1:${gateway.port};`],
    ["    listen 443 ssl;\n    listen [::]:443 ssl;\n", `    listen 127.0.0.1:${httpsPort} ssl;\n`],
    [`/etc/ssl/certs/${HOST}.pem`, cert],
    [`/etc/ssl/private/${HOST}.key`, key],
    // the test's stand-in for "nginx is another machine": its connections come from 127.0.0.2
    ["        proxy_pass http://rr_gateway/;\n", "        proxy_pass http://rr_gateway/;\n        proxy_bind 127.0.0.2;\n"],
  ], httpsPort);
  const { chromium } = webRequire("playwright-core");
  browser = await chromium.launch({
    executablePath: "/usr/bin/chromium", headless: true,
    args: [...CHROMIUM_ARGS, `--host-resolver-rules=MAP ${HOST} 127.0.0.1`],
  });
});

after(async () => {
  await browser?.close();
  await nginx?.stop();
  if (gateway) await gateway.child.stop();
  if (tmp) fs.rmSync(tmp, { recursive: true, force: true });
});

/** GET through nginx without a browser: { status, headers, body }. */
function get(pathname, headers = {}) {
  return new Promise((resolve, reject) => {
    https.get({ host: "127.0.0.1", port: new URL(site).port, path: pathname, servername: HOST, rejectUnauthorized: false,
      headers: { Host: new URL(site).host, ...headers } }, (r) => {
      let body = "";
      r.on("data", (d) => { body += d; });
      r.on("end", () => resolve({ status: r.statusCode, headers: r.headers, body }));
    }).on("error", reject);
  });
}

const gatewayLog = () => gateway.child.stderr.join("");

test("the gateway is at /rr/ only: / is the site's, /rr redirects to /rr/, the JSON API answers under /rr/", { skip: SKIP }, async () => {
  assert.equal((await get("/")).status, 404);
  const r = await get("/rr");
  assert.equal(r.status, 301);
  assert.match(r.headers.location, /\/rr\/$/);
  const page = await get("/rr/");
  assert.equal(page.status, 200);
  assert.match(page.body, /RR gateway dashboard/);
  const devices = await get("/rr/api/devices");
  assert.equal(devices.status, 200);
  assert.ok(JSON.parse(devices.body).some((d) => d.name === "create"));
});

test("Chromium: the dashboard under /rr/ over TLS shows a device with live data (rr+wss://…/rr/)", { skip: SKIP }, async () => {
  const context = await browser.newContext({ ignoreHTTPSErrors: true, viewport: { width: 1366, height: 900 } });
  const page = await context.newPage();
  const errors = [];
  page.on("pageerror", (e) => errors.push(String(e)));
  const outside = [];  // every request the page makes must stay under /rr/
  page.on("request", (r) => {
    const u = new URL(r.url());
    if (u.protocol.startsWith("http") || u.protocol.startsWith("ws")) {
      if (!u.pathname.startsWith("/rr/")) outside.push(r.url());
    }
  });
  await page.goto(`${site}/rr/#/create`);
  await page.locator('#device-list li[data-device="create"][data-state="connected"]').waitFor({ timeout: 60000 });
  const session = page.locator('.device-view[data-device="create"] .badge').nth(1);
  await waitFor(async () => (await session.textContent()) === "connected", "the page's RR session", 30000);
  assert.match(await page.locator(".event-log").textContent(),
    new RegExp(`connected to rr\\+wss://${HOST.replaceAll(".", "\\.")}:\\d+/rr/\\?service=create`));
  const dist = page.locator('.member[data-member="DistanceTraveled"]');
  const samples = async () => Number(await dist.locator(".plot").getAttribute("data-samples"));
  const n = await waitFor(samples, "distance samples");
  await waitFor(async () => (await samples()) > n + 3, "live data through nginx under /rr/");
  // the JSON WebSocket API from the page, relative to it
  const reply = await page.evaluate(() => new Promise((resolve, reject) => {
    const ws = new WebSocket(new URL(".", location.href).href.replace(/^http/, "ws"), "rr-gateway.json.v1");
    ws.onopen = () => ws.send(JSON.stringify({ id: 7, op: "devices" }));
    ws.onmessage = (m) => { const j = JSON.parse(m.data); if (j.id === 7) { ws.close(); resolve(j); } };
    ws.onerror = () => reject(new Error("JSON WebSocket failed"));
  }));
  assert.ok(reply.result.some((d) => d.name === "create"));
  fs.mkdirSync(s.artifacts, { recursive: true });
  await page.screenshot({ path: path.join(s.artifacts, "40-nginx-prefix.png") });
  assert.deepEqual(outside, []);
  assert.deepEqual(errors, []);
  // the gateway saw the browser (127.0.0.1) through the trusted proxy, over https
  assert.match(gatewayLog(), /WebSocket rr from 127\.0\.0\.1 \(https, via 127\.0\.0\.2:\d+\)/);
  assert.match(gatewayLog(), /WebSocket rr-gateway\.json\.v1 from 127\.0\.0\.1 \(https, via 127\.0\.0\.2:\d+\)/);
  await context.close();
});

test("X-Forwarded-For is taken from the trusted proxy only", { skip: SKIP }, async () => {
  const { WebSocket } = webRequire("ws");
  const open = (url, headers, options = {}) => new Promise((resolve, reject) => {
    const ws = new WebSocket(url, "rr-gateway.json.v1", { headers, ...options });
    ws.on("open", () => { ws.close(); resolve(); });
    ws.on("error", reject);
  });
  // through nginx: nginx appends the real peer (127.0.0.1, not a proxy) after what the client wrote
  await open(`wss://127.0.0.1:${new URL(site).port}/rr/`, { "X-Forwarded-For": "198.51.100.7", Host: new URL(site).host },
    { rejectUnauthorized: false, servername: HOST });
  // straight to the gateway from 127.0.0.1 (not a trusted proxy): the headers are ignored
  await open(`ws://127.0.0.1:${gateway.port}/`, { "X-Forwarded-For": "203.0.113.9", "X-Forwarded-Proto": "https" });
  await waitFor(() => /WebSocket rr-gateway\.json\.v1 from 127\.0\.0\.1:\d+\n/.test(gatewayLog()), "the direct client's log line");
  assert.doesNotMatch(gatewayLog(), /198\.51\.100\.7|203\.0\.113\.9/);
});
