// The dashboard behind nginx with TLS and logins (gateway-config/nginx-rr-gateway.conf, the file
// docs/deployment.md ships), in headless Chromium: the page, the JSON API and the client package's
// rr+wss session all go through nginx's basic-auth login. The file is used as shipped except for what
// a site changes (ports, certificate, password file, and the site's Origin, which here carries the
// test's port). Skipped when nginx or openssl is missing.

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import { execFileSync, spawn } from "node:child_process";
import fs from "node:fs";
import https from "node:https";
import net from "node:net";
import os from "node:os";
import path from "node:path";
import { settings, startGateway, launchChromium, waitFor, ROOT, CHROMIUM_ARGS, webRequire } from "./harness.mjs";
import { NGINX, HAVE_OPENSSL, freePort, substitute } from "./nginx_common.mjs";

const s = settings();
const SKIP = !NGINX || !HAVE_OPENSSL ? "nginx or openssl not installed (./scripts/setup.sh installs them)" : false;
const USER = "alice", PASSWORD = "wonderland", HOST = "lab.example.org";
let tmp, gateway, nginx, browser, site;

before(async () => {
  if (SKIP) return;
  tmp = fs.mkdtempSync(path.join(os.tmpdir(), "rr-web-nginx-"));
  fs.chmodSync(tmp, 0o755); // nginx workers (unprivileged) read the password file per request
  const httpsPort = await freePort(), httpPort = await freePort();
  site = `https://${HOST}:${httpsPort}`;
  // the gateway is reached through nginx, so the browser's Origin is the public site's
  gateway = await startGateway({ ...s }, {}, 0, ["--allow-origin", site]);
  const cert = path.join(tmp, "cert.pem"), key = path.join(tmp, "key.pem"), htpasswd = path.join(tmp, "htpasswd");
  execFileSync("openssl", ["req", "-x509", "-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:prime256v1", "-nodes",
    "-days", "1", "-subj", `/CN=${HOST}`, "-keyout", key, "-out", cert], { stdio: "ignore" });
  const hashed = execFileSync("openssl", ["passwd", "-apr1", PASSWORD]).toString().trim();
  fs.writeFileSync(htpasswd, `${USER}:${hashed}\n`, { mode: 0o644 });
  const conf = substitute(fs.readFileSync(path.join(ROOT, "gateway-config/nginx-rr-gateway.conf"), "utf8"), [
    ["server 127.0.0.1:8080;", `server 127.0.0.1:${gateway.port};`],
    ["    listen 80;\n    listen [::]:80;\n", `    listen 127.0.0.1:${httpPort};\n`],
    ["    listen 443 ssl;\n    listen [::]:443 ssl;\n", `    listen 127.0.0.1:${httpsPort} ssl;\n`],
    [`"https://${HOST}" 1;`, `"${site}" 1;`],
    [`/etc/ssl/certs/${HOST}.pem`, cert],
    [`/etc/ssl/private/${HOST}.key`, key],
    ["/etc/nginx/rr-gateway.htpasswd", htpasswd],
  ]);
  fs.writeFileSync(path.join(tmp, "site.conf"), conf);
  fs.writeFileSync(path.join(tmp, "nginx.conf"), `pid ${tmp}/nginx.pid;\nerror_log ${tmp}/error.log;\nevents {}\nhttp {\n`
    + `  access_log ${tmp}/access.log;\n  client_body_temp_path ${tmp}/body;\n  proxy_temp_path ${tmp}/proxy;\n`
    + `  include ${tmp}/site.conf;\n}\n`);
  nginx = spawn(NGINX, ["-p", tmp, "-c", path.join(tmp, "nginx.conf"), "-g", "daemon off;"], { stdio: "ignore" });
  await waitFor(() => new Promise((resolve) => {
    const c = net.connect(httpsPort, "127.0.0.1", () => { c.destroy(); resolve(true); });
    c.on("error", () => resolve(false));
  }), "nginx listening");
  const { chromium } = webRequire("playwright-core");
  browser = await chromium.launch({
    executablePath: "/usr/bin/chromium", headless: true,
    args: [...CHROMIUM_ARGS, `--host-resolver-rules=MAP ${HOST} 127.0.0.1`],
  });
});

after(async () => {
  await browser?.close();
  if (nginx && nginx.exitCode === null) {
    nginx.kill("SIGTERM");
    await new Promise((r) => nginx.once("exit", r));
  }
  if (gateway) await gateway.child.stop();
  if (tmp) fs.rmSync(tmp, { recursive: true, force: true });
});

test("nginx asks for the login; a browser without it gets no page", { skip: SKIP }, async () => {
  const status = (headers) => new Promise((resolve, reject) => {
    https.get({ host: "127.0.0.1", port: new URL(site).port, path: "/", servername: HOST, rejectUnauthorized: false,
      headers: { Host: new URL(site).host, ...headers } }, (r) => { r.resume(); resolve(r.statusCode); }).on("error", reject);
  });
  assert.equal(await status({}), 401);
  const login = `Basic ${Buffer.from(`${USER}:${PASSWORD}`).toString("base64")}`;
  assert.equal(await status({ Authorization: login }), 200);
  // a browser without the login cannot answer the challenge
  const context = await browser.newContext({ ignoreHTTPSErrors: true });
  await assert.rejects((await context.newPage()).goto(`${site}/`), /ERR_INVALID_AUTH_CREDENTIALS/);
  await context.close();
});

test("with a login the dashboard works over TLS (rr+wss through nginx)", { skip: SKIP }, async () => {
  const context = await browser.newContext({ ignoreHTTPSErrors: true, httpCredentials: { username: USER, password: PASSWORD },
    viewport: { width: 1366, height: 900 } });
  const page = await context.newPage();
  const errors = [];
  page.on("pageerror", (e) => errors.push(String(e)));
  if (process.env.RR_BROWSER_VERBOSE) {
    page.on("console", (m) => console.log("console:", m.text()));
    page.on("response", (r) => console.log("response:", r.status(), r.url()));
  }
  await page.goto(`${site}/#/create`);
  await page.locator('#device-list li[data-device="create"][data-state="connected"]').waitFor({ timeout: 60000 });
  const session = page.locator('.device-view[data-device="create"] .badge').nth(1);
  await waitFor(async () => (await session.textContent()) === "connected", "the page's RR session", 30000);
  assert.match(await page.locator(".event-log").textContent(), new RegExp(`connected to rr\\+wss://${HOST}:\\d+/\\?service=create`));
  const dist = page.locator('.member[data-member="DistanceTraveled"]');
  const samples = async () => Number(await dist.locator(".plot").getAttribute("data-samples"));
  const n = await waitFor(samples, "distance samples");
  await waitFor(async () => (await samples()) > n + 3, "the property polled through nginx");
  fs.mkdirSync(s.artifacts, { recursive: true });
  await page.screenshot({ path: path.join(s.artifacts, "30-nginx-tls.png") });
  assert.deepEqual(errors, []);
  await context.close();
});
