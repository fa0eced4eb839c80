// Runs one example of examples/ against rr-gateway's demo devices and checks what it prints.
//   node examples_test.mjs --gateway PATH cpp-client BINARY
//   node examples_test.mjs --gateway PATH cpp-service BINARY PYTHON   (the official Python client)
//   node examples_test.mjs --gateway PATH node-client
//   node examples_test.mjs --gateway PATH html                          (headless Chromium)
//   node examples_test.mjs --gateway PATH react                         (esbuild, headless Chromium)
// Exit 0 passed, 1 failed, 77 skipped (a part is missing: the reason is printed).
import { execFile, spawn } from "node:child_process";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";
import readline from "node:readline";
import { fileURLToPath } from "node:url";
import { promisify } from "node:util";

const ROOT = path.resolve(path.dirname(fileURLToPath(import.meta.url)), "../..");
const DIST = path.join(ROOT, "wasm-client/dist");
const args = process.argv.slice(2);
const gi = args.indexOf("--gateway");
const gatewayBin = args[gi + 1];
args.splice(gi, 2);
const [mode, ...rest] = args;
const run = promisify(execFile);

function skip(why) { console.log(`SKIP: ${why}`); process.exit(77); }
let failures = 0;
const ok = (cond, what) => { console.log(`${cond ? "ok" : "FAIL"}: ${what}`); if (!cond) failures++; };
const children = [];

/** Starts `cmd` and resolves with the first stdout JSON line holding `key`. */
function startJson(cmd, argv, key) {
  const proc = spawn(cmd, argv, { stdio: ["ignore", "pipe", "pipe"] });
  children.push(proc);
  let err = "";
  proc.stderr.on("data", (d) => { err += d; });
  const lines = [];
  const value = new Promise((resolve, reject) => {
    const rl = readline.createInterface({ input: proc.stdout });
    rl.on("line", (l) => { lines.push(l); try { const j = JSON.parse(l); if (key in j) resolve(j); } catch { /* not JSON */ } });
    proc.once("error", (e) => reject(new Error(`${cmd}: ${e.message}`)));
    proc.once("exit", (code) => reject(new Error(`${cmd} exited (${code}) before printing ${key}\n${err}`)));
    setTimeout(() => reject(new Error(`${cmd}: no ${key} line\n${err}`)), 60000);
  });
  return { proc, value, lines, stderr: () => err };
}

async function gateway(extra = []) {
  const g = startJson(gatewayBin, ["--listen", "127.0.0.1", "--port", "0", "--no-local", "--log-level", "warning", ...extra], "port");
  const { port } = await g.value;
  return { ...g, port, base: `http://127.0.0.1:${port}` };
}

async function waitDevices(base, names, timeoutMs = 60000) {
  const deadline = Date.now() + timeoutMs;
  for (;;) {
    const devices = await (await fetch(`${base}/api/devices`)).json();
    if (names.every((n) => devices.some((d) => d.name === n && d.state === "connected"))) return devices;
    if (Date.now() > deadline) throw new Error(`devices ${names} not connected: ${JSON.stringify(devices)}`);
    await new Promise((r) => setTimeout(r, 100));
  }
}

const modes = {
  async "cpp-client"() {
    const [binary] = rest;
    const g = await gateway();
    await waitDevices(g.base, ["create"]);
    for (const scheme of ["rr+tcp", "rr+ws"]) {
      const url = `${scheme}://127.0.0.1:${g.port}/?service=create`;
      try {
        const { stdout } = await run(binary, [url], { timeout: 60000 });
        process.stdout.write(`${stdout.trimEnd().replace(/^/gm, "  | ")}\n`);
        ok(/connected to .*experimental\.create\.Create/.test(stdout) && /DistanceTraveled = -?\d+ mm/.test(stdout)
          && /Drive\(200, 32767\): ok/.test(stdout) && /Drive\(1\.5\): RobotRaconteur\.\w+ \(as expected\)/.test(stdout)
          && /packets: ID \d+, \d+ data bytes, sent at \d+ s/.test(stdout) && /^done$/m.test(stdout), `C++ client over ${scheme}`);
        const d = [...stdout.matchAll(/DistanceTraveled = (-?\d+) mm/g)].map((m) => Number(m[1]));
        ok(d.length === 2 && d[1] > d[0], `the robot moved after Drive: ${d.join(" -> ")} mm`);
      } catch (e) {
        ok(false, `C++ client over ${scheme}: ${e.message}\n${e.stdout ?? ""}${e.stderr ?? ""}`);
      }
    }
    // a service that is not there: a clear error and exit 1
    try {
      await run(binary, [`rr+tcp://127.0.0.1:${g.port}/?service=nope`], { timeout: 60000 });
      ok(false, "a missing service must fail");
    } catch (e) {
      ok(e.code === 1 && /connect failed: RobotRaconteur\.ServiceNotFound/.test(e.stderr), `missing service: ${e.stderr.trim()}`);
    }
  },

  async "cpp-service"() {
    const [binary, python] = rest;
    if (!python || !fs.existsSync(python)) skip(`${python}: the official client's venv is missing (./scripts/setup.sh)`);
    const svc = startJson(binary, ["0"], "url");
    const { url } = await svc.value;
    ok(/^rr\+tcp:\/\/127\.0\.0\.1:\d+\/\?service=counter$/.test(url), `service at ${url}`);
    // the official Python client (robotraconteur, test/interop/requirements.txt)
    const script = `
import sys, time
from RobotRaconteur.Client import *
c = RRN.ConnectService(sys.argv[1])
seen = []
c.changed += lambda n: seen.append(n)
print("count", c.count)
print("add", c.add(5), c.add(2))
try:
    c.add(-1)
except Exception as e:
    print("error", type(e).__name__, e)
for _ in range(50):
    if len(seen) >= 2: break
    time.sleep(0.1)
print("events", sorted(seen))  # its thread pool may run the two handlers in either order
RRN.DisconnectService(c)
`;
    try {
      const { stdout } = await run(python, ["-c", script, url], { timeout: 60000 });
      process.stdout.write(`${stdout.trimEnd().replace(/^/gm, "  | ")}\n`);
      ok(/^count 0$/m.test(stdout) && /^add 5 7$/m.test(stdout), "official client: property and function");
      ok(/^error InvalidArgumentException .*n must be positive/m.test(stdout), "official client: the service's error");
      ok(/^events \[5, 7\]$/m.test(stdout), "official client: the event");
    } catch (e) {
      ok(false, `official client: ${e.message}\n${e.stdout ?? ""}${e.stderr ?? ""}`);
    }
    // the same service as a gateway device
    const g = await gateway(["--no-demo", "--device", `counter=${url}`]);
    const devices = await waitDevices(g.base, ["counter"]);
    ok(devices.find((d) => d.name === "counter").object_type === "example.counter.Counter", "rr-gateway serves it as a device");
    g.proc.kill("SIGTERM");
    svc.proc.kill("SIGTERM");
    const code = await new Promise((r) => (svc.proc.exitCode !== null ? r(svc.proc.exitCode) : svc.proc.once("exit", r)));
    ok(code === 0 && svc.lines.includes("stopped"), `SIGTERM stops the service (exit ${code})`);
  },

  async "node-client"() {
    if (!fs.existsSync(path.join(DIST, "robotraconteur_wasm.wasm"))) skip("wasm-client/dist not built (wasm-client/build.sh)");
    const ws = path.join(ROOT, "wasm-client/node_modules/ws");
    if (!fs.existsSync(ws)) skip("wasm-client/node_modules missing (./scripts/setup.sh)");
    const tmp = fs.mkdtempSync(path.join(os.tmpdir(), "rr-example-node-"));
    try {
      // what `npm install` of package.json gives: the package and ws in node_modules
      fs.copyFileSync(path.join(ROOT, "examples/node-client/client.mjs"), path.join(tmp, "client.mjs"));
      fs.mkdirSync(path.join(tmp, "node_modules"));
      fs.symlinkSync(DIST, path.join(tmp, "node_modules/robotraconteur-wasm"), "dir");
      fs.symlinkSync(ws, path.join(tmp, "node_modules/ws"), "dir");
      const g = await gateway();
      await waitDevices(g.base, ["create"]);
      const { stdout } = await run(process.execPath, [path.join(tmp, "client.mjs"), `rr+ws://127.0.0.1:${g.port}/?service=create`],
        { cwd: tmp, timeout: 60000 });
      process.stdout.write(`${stdout.trimEnd().replace(/^/gm, "  | ")}\n`);
      ok(/connected to .*experimental\.create\.Create/.test(stdout) && /DistanceTraveled = -?\d+ mm/.test(stdout)
        && /Drive\(1\.5\): RobotRaconteur\.\w+ \(as expected\)/.test(stdout) && /packets: ID \d+, \d+ data bytes/.test(stdout)
        && /^done$/m.test(stdout), "node client");
    } finally {
      fs.rmSync(tmp, { recursive: true, force: true });
    }
  },

  async html() {
    if (!fs.existsSync(path.join(DIST, "robotraconteur_wasm.wasm"))) skip("wasm-client/dist not built (wasm-client/build.sh)");
    if (!fs.existsSync("/usr/bin/chromium")) skip("/usr/bin/chromium missing (./scripts/setup.sh)");
    const pw = path.join(ROOT, "web/node_modules/playwright-core");
    if (!fs.existsSync(pw)) skip("web/node_modules missing (./scripts/setup.sh)");
    const tmp = fs.mkdtempSync(path.join(os.tmpdir(), "rr-example-html-"));
    let browser;
    try {
      // the site as the page's comment says: index.html with the package in rr/
      fs.copyFileSync(path.join(ROOT, "examples/html/index.html"), path.join(tmp, "index.html"));
      fs.cpSync(DIST, path.join(tmp, "rr"), { recursive: true });
      const g = await gateway(["--web-root", tmp]);
      await waitDevices(g.base, ["create"]);
      const { chromium } = (await import(path.join(pw, "index.mjs"))).default ?? (await import(path.join(pw, "index.mjs")));
      browser = await chromium.launch({ executablePath: "/usr/bin/chromium", headless: true,
        args: ["--no-sandbox", "--disable-gpu", "--disable-background-networking", "--no-first-run"] });
      const page = await browser.newPage();
      const errors = [];
      page.on("pageerror", (e) => errors.push(String(e)));
      await page.goto(`${g.base}/`);
      await page.waitForFunction(() => Number(document.getElementById("packet").dataset.count ?? 0) >= 3, null, { timeout: 60000 })
        .catch(async (e) => { throw new Error(`${e.message}; page: ${await page.textContent("body")}; errors: ${errors}`); });
      ok(/^connected \(experimental\.create\.Create\)$/.test(await page.textContent("#state")), "the page connected");
      const before = Number(await page.textContent("#distance"));
      ok(Number.isInteger(before), `distance ${before}`);
      // the button drives and then reads the distance: pressed again (each press reads it anew) until the
      // robot's move shows, bounded against a hang only (the demo's clock advances the robot, not the press)
      const deadline = Date.now() + 60000;
      for (;;) {
        await page.click("#drive");
        const moved = await page.waitForFunction((b) => Number(document.getElementById("distance").textContent) > b, before, { timeout: 1000 })
          .then(() => true, () => false);
        if (moved) break;
        if (Date.now() > deadline) throw new Error(`Drive: the distance stayed ${await page.textContent("#distance")} mm for 30 s`);
      }
      ok(true, `Drive moved the robot: ${before} -> ${await page.textContent("#distance")} mm`);
      ok(errors.length === 0, `no page errors ${errors.join("; ")}`);
    } finally {
      await browser?.close();
      fs.rmSync(tmp, { recursive: true, force: true });
    }
  },

  // examples/react built as its README says (npm ci, npm run build: esbuild), served with the package in
  // rr/; the gateway is then stopped and started again on the same port: the page must show the wire
  // again by itself (the subscription reconnects; the hook shows the second connection).
  async react() {
    if (!fs.existsSync(path.join(DIST, "robotraconteur_wasm.wasm"))) skip("wasm-client/dist not built (wasm-client/build.sh)");
    if (!fs.existsSync("/usr/bin/chromium")) skip("/usr/bin/chromium missing (./scripts/setup.sh)");
    const pw = path.join(ROOT, "web/node_modules/playwright-core");
    if (!fs.existsSync(pw)) skip("web/node_modules missing (./scripts/setup.sh)");
    const ex = path.join(ROOT, "examples/react");
    if (!fs.existsSync(path.join(ex, "node_modules/esbuild"))) skip("examples/react/node_modules missing (./scripts/setup.sh runs npm ci there)");
    const tmp = fs.mkdtempSync(path.join(os.tmpdir(), "rr-example-react-"));
    let browser;
    try {
      const { stdout } = await run(process.execPath, [path.join(ex, "build.mjs")], { cwd: ex, timeout: 60000 });
      ok(/built dist\/app\.js/.test(stdout), "esbuild bundled the React app");
      fs.copyFileSync(path.join(ex, "index.html"), path.join(tmp, "index.html"));
      fs.cpSync(path.join(ex, "dist"), path.join(tmp, "dist"), { recursive: true });
      fs.cpSync(DIST, path.join(tmp, "rr"), { recursive: true });
      let g = await gateway(["--web-root", tmp]);
      const port = g.port;
      await waitDevices(g.base, ["create"]);
      const { chromium } = (await import(path.join(pw, "index.mjs"))).default ?? (await import(path.join(pw, "index.mjs")));
      browser = await chromium.launch({ executablePath: "/usr/bin/chromium", headless: true,
        args: ["--no-sandbox", "--disable-gpu", "--disable-background-networking", "--no-first-run"] });
      const page = await browser.newPage();
      const errors = [];
      page.on("pageerror", (e) => errors.push(String(e)));
      await page.goto(`${g.base}/`);
      const packetAfter = async (what, connects) => {
        await page.waitForFunction((n) => document.getElementById("state")?.textContent === "connected"
          && Number(document.getElementById("connects").textContent) >= n && /^ID \d+/.test(document.getElementById("packet").textContent),
        connects, { timeout: 60000 })
          .catch(async (e) => { throw new Error(`${e.message}; page: ${await page.textContent("body")}; errors: ${errors}`); });
        const first = Number(await page.textContent("#count"));
        await page.waitForFunction((n) => Number(document.getElementById("count").textContent) >= n + 2, first, { timeout: 60000 });
        ok(true, `${what}: ${await page.textContent("#packet")}, connections ${await page.textContent("#connects")}`);
      };
      await packetAfter("the hook shows the wire", 1);
      g.proc.kill("SIGKILL");
      await new Promise((r) => g.proc.once("exit", r));
      await page.waitForFunction(() => document.getElementById("state").textContent === "reconnecting", null, { timeout: 20000 });
      ok(true, "the page shows the lost connection");
      for (let i = 0; ; i++) {  // the port a killed process held can take a moment to bind again
        try {
          const again = startJson(gatewayBin, ["--listen", "127.0.0.1", "--port", String(port), "--no-local", "--log-level", "warning",
            "--web-root", tmp], "port");
          await again.value;
          g = { ...again, port, base: `http://127.0.0.1:${port}` };
          break;
        } catch (e) {
          if (i > 20) throw e;
          await new Promise((r) => setTimeout(r, 200));
        }
      }
      await waitDevices(g.base, ["create"]);
      await packetAfter("after the gateway restarted, by itself", 2);
      ok(errors.length === 0, `no page errors ${errors.join("; ")}`);
    } finally {
      await browser?.close();
      fs.rmSync(tmp, { recursive: true, force: true });
    }
  },
};

if (!modes[mode]) { console.error(`unknown mode ${mode}`); process.exit(2); }
try {
  await modes[mode]();
} catch (e) {
  ok(false, e.stack ?? String(e));
} finally {
  for (const c of children) if (c.exitCode === null && c.signalCode === null) c.kill("SIGTERM");
}
console.log(failures ? `${failures} failure(s)` : "all passed");
process.exit(failures ? 1 : 0);
