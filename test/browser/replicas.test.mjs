// Two rr-gateway replicas behind nginx (gateway-config/nginx-rr-gateway-replicas.conf), then behind
// HAProxy (gateway-config/haproxy-rr-gateway-replicas.cfg), each file as shipped but for ports and
// certificates, under /rr/ with TLS. Dashboards in separate Chromium contexts (separate
// cookies) are spread over both replicas by the sticky cookie; each shows live data from its replica.
// One replica is killed (SIGKILL): the dashboards it served lose their RR session, reconnect through
// nginx, land on the other replica and show live data again; the others are not disturbed.
// The replica serving a page is read from a header the test adds (X-RR-Replica: the upstream address
// for nginx, the server name for HAProxy). Each balancer's test is skipped when it is not installed.

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";
import { settings, startGateway, waitFor, CHROMIUM_ARGS, webRequire, ROOT } from "./harness.mjs";
import { spawn } from "node:child_process";
import net from "node:net";
import { NGINX, HAVE_OPENSSL, freePort, selfSignedCert, startNginx, substitute } from "./nginx_common.mjs";

const s = settings();
const HAPROXY = ["/usr/sbin/haproxy", "/usr/bin/haproxy"].find((p) => fs.existsSync(p));
const NO_TLS = !HAVE_OPENSSL ? "openssl not installed" : false;
const SKIP_NGINX = NO_TLS || (!NGINX ? "nginx not installed (./scripts/setup.sh installs it)" : false);
const SKIP_HAPROXY = NO_TLS || (!HAPROXY ? "haproxy not installed (apt-get install haproxy)" : false);
const HOST = "site.example.org";
const MAX_PAGES = 12;
let browser, site, replicas, tmp, balancer;

async function startReplicas() {
  tmp = fs.mkdtempSync(path.join(os.tmpdir(), "rr-web-replicas-"));
  fs.chmodSync(tmp, 0o755);
  replicas = [];
  for (let i = 0; i < 2; i++)
    replicas.push(await startGateway({ ...s }, {}, 0, ["--log-level", "info", "--trusted-proxy", "127.0.0.1"]));
  const httpsPort = await freePort();
  site = `https://${HOST}:${httpsPort}`;
  return httpsPort;
}

async function startHaproxy(port) {
  const { cert, key } = selfSignedCert(tmp, HOST);
  const pem = path.join(tmp, "site.pem");
  fs.writeFileSync(pem, fs.readFileSync(cert, "utf8") + fs.readFileSync(key, "utf8"));
  const cfg = substitute(fs.readFileSync(path.join(ROOT, "gateway-config/haproxy-rr-gateway-replicas.cfg"), "utf8"), [
    ["server r1 127.0.0.1:8081 ", `server r1 127.0.0.1:${replicas[0].port} `],
    ["server r2 127.0.0.1:8082 ", `server r2 127.0.0.1:${replicas[1].port} `],
    ["    bind :443 ssl crt /etc/haproxy/certs/site.example.org.pem\n", `    bind 127.0.0.1:${port} ssl crt ${pem}\n`],
    ["    option forwardfor\n", "    option forwardfor\n    http-response set-header X-RR-Replica %[srv_name]\n"],
  ]);
  fs.writeFileSync(path.join(tmp, "haproxy.cfg"), cfg);
  const proc = spawn(HAPROXY, ["-db", "-f", path.join(tmp, "haproxy.cfg")], { stdio: ["ignore", "ignore", "pipe"] });
  let err = "";
  proc.stderr.on("data", (d) => { err += d; });
  const exited = new Promise((r) => proc.once("exit", r));
  await Promise.race([
    waitFor(() => new Promise((resolve) => {
      const c = net.connect(port, "127.0.0.1", () => { c.destroy(); resolve(true); });
      c.on("error", () => resolve(false));
    }), "haproxy listening"),
    exited.then(() => { throw new Error(`haproxy exited: ${err}`); }),
  ]);
  return { names: { r1: `127.0.0.1:${replicas[0].port}`, r2: `127.0.0.1:${replicas[1].port}` },
    async stop() { if (proc.exitCode === null && proc.signalCode === null) { proc.kill("SIGTERM"); await exited; } } };
}

async function startNginxBalancer(port) {
  const { cert, key } = selfSignedCert(tmp, HOST);
  const n = await startNginx(tmp, "nginx-rr-gateway-replicas.conf", [
    ["server 127.0.0.1:8081 ", `server 127.0.0.1:${replicas[0].port} `],
    ["server 127.0.0.1:8082 ", `server 127.0.0.1:${replicas[1].port} `],
    ["    listen 443 ssl;\n    listen [::]:443 ssl;\n", `    listen 127.0.0.1:${port} ssl;\n`],
    [`/etc/ssl/certs/${HOST}.pem`, cert],
    [`/etc/ssl/private/${HOST}.key`, key],
    ["        proxy_pass http://rr_gateways/;\n", "        proxy_pass http://rr_gateways/;\n        add_header X-RR-Replica $upstream_addr always;\n"],
  ], port);
  return { names: {}, stop: () => n.stop() };
}

before(async () => {
  if (SKIP_NGINX && SKIP_HAPROXY) return;
  const { chromium } = webRequire("playwright-core");
  browser = await chromium.launch({
    executablePath: "/usr/bin/chromium", headless: true,
    args: [...CHROMIUM_ARGS, `--host-resolver-rules=MAP ${HOST} 127.0.0.1`],
  });
});

async function stopAll() {
  await balancer?.stop();
  for (const r of replicas ?? []) await r.child.stop();
  if (tmp) fs.rmSync(tmp, { recursive: true, force: true });
  balancer = replicas = tmp = undefined;
}

after(async () => {
  await stopAll();
  await browser?.close();
});

/** One dashboard in its own context (its own cookie jar), on device `create`. */
async function openDashboard() {
  const context = await browser.newContext({ ignoreHTTPSErrors: true, viewport: { width: 1100, height: 800 } });
  const page = await context.newPage();
  const errors = [];
  page.on("pageerror", (e) => errors.push(String(e)));
  await page.goto(`${site}/rr/#/create`);
  const badge = page.locator('.device-view[data-device="create"] .badge').nth(1);
  const plot = page.locator('.member[data-member="DistanceTraveled"] .plot');
  const d = {
    context, page, errors,
    state: async () => badge.textContent(),
    samples: async () => Number(await plot.getAttribute("data-samples")),
    /** The replica (host:port) answering this page's requests now. */
    replica: () => page.evaluate(async () => (await fetch("api/devices", { cache: "no-store" })).headers.get("x-rr-replica")),
    /** From now on, remembers in the page whether the session badge leaves "connected": the page may
     * reconnect faster than a poll sees it disconnected. */
    watchDrop: () => page.evaluate(() => {
      const el = document.querySelectorAll('.device-view[data-device="create"] .badge')[1];
      window.rrDropped = false;
      new MutationObserver(() => { if (el.textContent !== "connected") window.rrDropped = true; })
        .observe(el, { childList: true, characterData: true, subtree: true, attributes: true });
    }),
    dropped: () => page.evaluate(() => window.rrDropped === true),
    async live(what) {
      await waitFor(async () => (await d.state()) === "connected", `${what}: RR session`, 40000);
      const n = await waitFor(d.samples, `${what}: samples`, 20000);
      await waitFor(async () => (await d.samples()) > n + 3, `${what}: live data`, 20000);
    },
  };
  await d.live("new dashboard");
  return d;
}

async function failover(start) {
  balancer = await start(await startReplicas());
  const addr = replicas.map((r) => `127.0.0.1:${r.port}`);
  const pages = [];
  const on = (i) => pages.filter((p) => p.at === addr[i]);
  while ((on(0).length < 2 || on(1).length < 2) && pages.length < MAX_PAGES) {
    const d = await openDashboard();
    d.at = await d.replica();
    d.at = balancer.names[d.at] ?? d.at;
    assert.ok(addr.includes(d.at), `answered by ${d.at}, not a replica`);
    // the RR WebSocket of this page went to the same replica (the sticky cookie): its log has one more
    pages.push(d);
  }
  assert.ok(on(0).length >= 1 && on(1).length >= 1, `pages on the replicas: ${on(0).length}, ${on(1).length}`);
  const wsLines = (r) => (r.child.stderr.join("").match(/WebSocket rr from 127\.0\.0\.1 \(https, via /g) || []).length;
  assert.ok(wsLines(replicas[0]) >= on(0).length && wsLines(replicas[1]) >= on(1).length,
    `RR WebSockets per replica ${wsLines(replicas[0])}, ${wsLines(replicas[1])} for pages ${on(0).length}, ${on(1).length}`);
  // every page is still on the replica that served it first (sticky)
  // nginx's $upstream_addr lists every replica it tried for the request ("dead:port, alive:port" while
  // the sticky one is down): the last one answered.
  const at = async (d) => { const r = (await d.replica()).split(", ").at(-1); return balancer.names[r] ?? r; };
  for (const d of pages) assert.equal(await at(d), d.at);

  const victim = 0, survivor = 1;
  const moved = on(victim), stayed = on(survivor);
  for (const d of moved) await d.watchDrop();
  replicas[victim].child.proc.kill("SIGKILL");
  await replicas[victim].child.exited;
  for (const d of moved)
    await waitFor(d.dropped, "the dashboard notices its replica is gone", 20000);
  for (const [i, d] of moved.entries()) {
    await d.live(`moved dashboard ${i}`);
    assert.equal(await at(d), addr[survivor]);
  }
  for (const [i, d] of stayed.entries()) {
    await d.live(`undisturbed dashboard ${i}`);
    assert.equal(await at(d), addr[survivor]);
  }
  fs.mkdirSync(s.artifacts, { recursive: true });
  await moved[0].page.screenshot({ path: path.join(s.artifacts, `41-replica-failover-${start.name}.png`) });
  for (const d of pages) {
    assert.deepEqual(d.errors, []);
    await d.context.close();
  }
}

test("nginx: dashboards spread over two replicas; one dies; its dashboards reconnect to the other", { skip: SKIP_NGINX, timeout: 240000 },
  async () => { try { await failover(startNginxBalancer); } finally { await stopAll(); } });

test("HAProxy: dashboards spread over two replicas; one dies; its dashboards reconnect to the other", { skip: SKIP_HAPROXY, timeout: 240000 },
  async () => { try { await failover(startHaproxy); } finally { await stopAll(); } });
