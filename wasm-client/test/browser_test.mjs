// Runs api.html (the same API checks as node_test.mjs) inside headless Debian Chromium through
// playwright-core (web/node_modules), against rr-gateway in front of rr_interop_service. The gateway
// serves wasm-client/ as its web root, so the page and its WebSocket share one origin.
//
// Usage: node browser_test.mjs --interop-service PATH --gateway PATH [--only REGEX]
// Exit: 0 all passed, 1 a check failed, 2 setup failed, 77 Chromium, playwright-core or emscripten absent.
import { spawn } from "node:child_process";
import { mkdtempSync, rmSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { createInterface } from "node:readline";
import { dirname, join } from "node:path";
import { fileURLToPath } from "node:url";
import { CHROMIUM, chromiumOrSkip } from "./chromium_setup.mjs";

const here = dirname(fileURLToPath(import.meta.url));
const pkgRoot = join(here, "..");

function arg(name, fallback = null) {
  const i = process.argv.indexOf(name);
  return i > 0 && i + 1 < process.argv.length ? process.argv[i + 1] : fallback;
}

const pw = chromiumOrSkip();

const children = [];
function start(cmd, args) {
  const p = spawn(cmd, args, { stdio: ["ignore", "pipe", "inherit"] });
  children.push(p);
  return p;
}
const stopAll = () => children.forEach((p) => p.exitCode === null && p.signalCode === null && p.kill("SIGTERM"));
process.on("exit", stopAll);

function readyLine(p, key, timeoutMs = 60000) {
  return new Promise((resolve, reject) => {
    const t = setTimeout(() => reject(new Error(`no ready line with "${key}"`)), timeoutMs);
    p.on("exit", (code) => reject(new Error(`exited early with ${code}`)));
    createInterface({ input: p.stdout }).on("line", (line) => {
      try {
        const o = JSON.parse(line);
        if (key in o) {
          clearTimeout(t);
          resolve(o);
        }
      } catch {
        // not the ready line
      }
    });
  });
}

let browser;
let code = 2;
try {
  const svc = start(arg("--interop-service"), ["--port", "0", "--max-lifetime", "300"]);
  const dev = await readyLine(svc, "url");
  // `auth: passthrough` (docs/security.md): the page gets its own session to the device, so the monitor
  // lock check locks on the device itself (a shared device refuses locks), as in node_test.mjs.
  const configDir = mkdtempSync(join(tmpdir(), "rr-wasm-browser-"));
  process.on("exit", () => rmSync(configDir, { recursive: true, force: true }));
  const config = join(configDir, "gateway.yaml");
  writeFileSync(config, `devices:\n  - name: interop\n    url: ${JSON.stringify(dev.url)}\n    auth: passthrough\n`);
  const gw = start(arg("--gateway"), ["--config", config, "--no-demo", "--no-local", "--listen", "127.0.0.1", "--port", "0",
    "--log-level", "warning", "--web-root", pkgRoot]);
  const { port } = await readyLine(gw, "port");
  for (let i = 0; ; i++) {
    const r = await fetch(`http://127.0.0.1:${port}/readyz`).catch(() => null);
    if (r?.status === 200) break;
    if (i > 300) throw new Error("gateway not ready");
    await new Promise((r) => setTimeout(r, 100));
  }
  browser = await pw.launch({ executablePath: CHROMIUM, headless: true,
    args: ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run", "--disable-background-networking",
      "--disable-component-update", "--disable-sync"] });
  const page = await browser.newPage();
  page.on("console", (m) => m.type() === "error" && console.log(`  [console] ${m.text()}`));
  page.on("pageerror", (e) => console.log(`  [pageerror] ${e.message}`));
  const only = arg("--only") ? `&only=${encodeURIComponent(arg("--only"))}` : "";
  const url = `http://127.0.0.1:${port}/test/api.html?url=${encodeURIComponent(`rr+ws://127.0.0.1:${port}/?service=interop`)}${only}`;
  console.log(`== chromium ${browser.version()}: ${url}`);
  await page.goto(url);
  await page.waitForFunction(() => window.__result?.done === true, null, { timeout: 540000 });
  const r = await page.evaluate(() => window.__result);
  for (const n of r.passed) console.log(`  ok   ${n}`);
  for (const f of r.failed) console.log(`  FAIL ${f.name}: ${f.error}`);
  console.log(`== chromium: ${r.passed.length} passed, ${r.failed.length} failed`);
  code = r.failed.length || !r.passed.length ? 1 : 0;  // nothing run is not a pass
} catch (e) {
  console.error(`browser test: ${e.message}`);
  code = 2;
} finally {
  await browser?.close();
  stopAll();
}
process.exit(code);
