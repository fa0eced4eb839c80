// The dashboard served over HTTPS by the gateway itself (gateway.tls, docs/security.md), in headless
// Chromium: the page comes over https://, the wasm client's RR session runs over rr+wss:// to the same
// origin (the browser's own TLS), the JSON API answers over HTTPS, and the same port still serves
// plain HTTP. The certificate is made with the openssl CLI; the browser context accepts it as a
// self-signed site (ignoreHTTPSErrors). Skipped when openssl is missing.

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import { execFileSync } from "node:child_process";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";
import { settings, startGateway, launchChromium, waitFor } from "./harness.mjs";

const s = settings();
const HAVE_OPENSSL = (() => { try { execFileSync("openssl", ["version"]); return true; } catch { return false; } })();
const SKIP = !HAVE_OPENSSL ? "openssl not installed (./scripts/setup.sh installs it)" : false;
let tmp, gateway, browser, base;

before(async () => {
  if (SKIP) return;
  tmp = fs.mkdtempSync(path.join(os.tmpdir(), "rr-web-https-"));
  const cert = path.join(tmp, "cert.pem"), key = path.join(tmp, "key.pem");
  execFileSync("openssl", ["req", "-x509", "-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:prime256v1", "-nodes",
    "-days", "1", "-subj", "/CN=127.0.0.1", "-addext", "subjectAltName=IP:127.0.0.1,DNS:localhost",
    "-keyout", key, "-out", cert], { stdio: "ignore" });
  gateway = await startGateway(s, {}, 0, ["--tls-certificate", cert, "--tls-private-key", key]);
  base = `https://127.0.0.1:${gateway.port}`;
  browser = await launchChromium();
});

after(async () => {
  await browser?.close();
  if (gateway) await gateway.child.stop();
  if (tmp) fs.rmSync(tmp, { recursive: true, force: true });
});

test("the dashboard over HTTPS from the gateway: rr+wss to the same origin", { skip: SKIP }, async () => {
  const context = await browser.newContext({ ignoreHTTPSErrors: true, viewport: { width: 1366, height: 900 } });
  const page = await context.newPage();
  const errors = [];
  const sockets = [];
  page.on("pageerror", (e) => errors.push(String(e)));
  page.on("websocket", (ws) => sockets.push(ws.url()));
  await page.goto(`${base}/#/create`);
  assert.equal(await page.evaluate(() => location.protocol), "https:");
  await page.locator('#device-list li[data-device="create"][data-state="connected"]').waitFor({ timeout: 60000 });
  const session = page.locator('.device-view[data-device="create"] .badge').nth(1);
  await waitFor(async () => (await session.textContent()) === "connected", "the page's RR session", 30000);
  assert.match(await page.locator(".event-log").textContent(),
    new RegExp(`connected to rr\\+wss://127\\.0\\.0\\.1:${gateway.port}/\\?service=create`));
  // Every WebSocket the page opened is wss:// to the origin it came from.
  assert.ok(sockets.length > 0, "no WebSocket opened");
  for (const url of sockets) assert.ok(url.startsWith(`wss://127.0.0.1:${gateway.port}/`), url);
  // Values flow: the distance plot gets samples through the TLS WebSocket.
  const dist = page.locator('.member[data-member="DistanceTraveled"]');
  const samples = async () => Number(await dist.locator(".plot").getAttribute("data-samples"));
  const n = await waitFor(samples, "distance samples");
  await waitFor(async () => (await samples()) > n + 3, "the property polled over rr+wss");
  // The JSON API from the page, same origin over HTTPS.
  const names = await page.evaluate(async () => (await (await fetch("/api/devices")).json()).map((d) => d.name));
  assert.deepEqual(names, ["create", "webcam"]);
  fs.mkdirSync(s.artifacts, { recursive: true });
  await page.screenshot({ path: path.join(s.artifacts, "40-gateway-https.png") });
  assert.deepEqual(errors, []);
  await context.close();
});

test("the same port still serves the dashboard over plain HTTP", { skip: SKIP }, async () => {
  const r = await fetch(`http://127.0.0.1:${gateway.port}/livez`);
  assert.equal(r.status, 200);
  const context = await browser.newContext();
  const page = await context.newPage();
  await page.goto(`http://127.0.0.1:${gateway.port}/#/create`);
  await page.locator('#device-list li[data-device="create"][data-state="connected"]').waitFor({ timeout: 60000 });
  await context.close();
});
