// Runs api_checks.mjs with the BUILT package (wasm-client/dist) in node against three services:
//   1. rr_interop_service --websocket (our C++ service), rr+ws
//   2. rr-gateway in front of it (device over rr+tcp, client over rr+ws to the gateway)
//   3. the official Python service (test/interop/official_service.py), rr+ws on its TCP port
//   4. the official service with message format v2 only; 5. ours with v4 string tables
//
// Usage: node node_test.mjs --interop-service PATH --gateway PATH --python PATH [--only REGEX] [--target NAME]
// Exit: 0 all passed, 1 a check failed, 2 setup failed, 77 emscripten absent (package cannot be built).
import { spawn, spawnSync } from "node:child_process";
import { existsSync } from "node:fs";
import { createInterface } from "node:readline";
import { fileURLToPath } from "node:url";
import { dirname, join } from "node:path";

const here = dirname(fileURLToPath(import.meta.url));
const root = join(here, "..", "..");
const dist = join(here, "..", "dist", "robotraconteur.mjs");

function arg(name, fallback = null) {
  const i = process.argv.indexOf(name);
  return i > 0 && i + 1 < process.argv.length ? process.argv[i + 1] : fallback;
}

if (!existsSync(dist)) {
  if (spawnSync("sh", ["-c", "command -v emcmake"]).status !== 0) {
    console.log("SKIP: emscripten is not installed, so wasm-client/dist cannot be built (run scripts/setup.sh)");
    process.exit(77);
  }
  console.error(`${dist} missing: run wasm-client/build.sh (scripts/test.sh does)`);
  process.exit(2);
}

const children = [];
function start(cmd, args) {
  const p = spawn(cmd, args, { stdio: ["ignore", "pipe", "inherit"] });
  children.push(p);
  return p;
}
function stopAll() {
  for (const p of children) if (p.exitCode === null && p.signalCode === null) p.kill("SIGTERM");
}
process.on("exit", stopAll);

/** The first stdout line of `p` that is JSON with `key`. */
function readyLine(p, key, timeoutMs = 60000) {
  return new Promise((resolve, reject) => {
    const t = setTimeout(() => reject(new Error(`no ready line with "${key}" in ${timeoutMs} ms`)), timeoutMs);
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

async function gatewayReady(port, timeoutMs = 30000) {
  const end = Date.now() + timeoutMs;
  for (;;) {
    try {
      const r = await fetch(`http://127.0.0.1:${port}/readyz`);
      if (r.status === 200) return;
    } catch {
      // not listening yet
    }
    if (Date.now() > end) throw new Error("gateway not ready (/readyz)");
    await new Promise((r) => setTimeout(r, 100));
  }
}

const targets = {
  async ours() {
    const svc = start(arg("--interop-service"), ["--port", "0", "--websocket", "--max-lifetime", "300"]);
    return (await readyLine(svc, "ws_url")).ws_url;
  },
  async gateway() {
    const svc = start(arg("--interop-service"), ["--port", "0", "--max-lifetime", "300"]);
    const dev = await readyLine(svc, "url");
    const gw = start(arg("--gateway"), ["--no-demo", "--listen", "127.0.0.1", "--port", "0", "--log-level", "warning",
      "--device", `interop=${dev.url}`]);
    const { port } = await readyLine(gw, "port");
    await gatewayReady(port);
    return `rr+ws://127.0.0.1:${port}/?service=interop`;
  },
  async official() {
    const py = arg("--python", join(root, ".venv", "bin", "python"));
    const svc = start(py, [join(root, "test", "interop", "official_service.py"), "--port", "0", "--websocket",
      "--max-lifetime", "300"]);
    return (await readyLine(svc, "ws_url")).ws_url;
  },
  // Message format v2 only (no v4 negotiated), and v4 with string tables.
  async "official-v2"() {
    const py = arg("--python", join(root, ".venv", "bin", "python"));
    const svc = start(py, [join(root, "test", "interop", "official_service.py"), "--port", "0", "--websocket",
      "--disable-message4", "--max-lifetime", "300"]);
    return (await readyLine(svc, "ws_url")).ws_url;
  },
  async "ours-stringtable"() {
    const svc = start(arg("--interop-service"), ["--port", "0", "--websocket", "--enable-stringtable",
      "--max-lifetime", "300"]);
    return (await readyLine(svc, "ws_url")).ws_url;
  },
};

const rr = await import(dist);
const { runChecks } = await import("./api_checks.mjs");
const only = arg("--only") ? new RegExp(arg("--only")) : null;
const chosen = arg("--target") ? [arg("--target")] : Object.keys(targets);
let failed = 0;
for (const name of chosen) {
  let url;
  try {
    url = await targets[name]();
  } catch (e) {
    console.error(`${name}: setup failed: ${e.message}`);
    stopAll();
    process.exit(2);
  }
  console.log(`== ${name}: ${url}`);
  const report = await runChecks(rr, url, { log: (l) => console.log(`  ${l}`), only });
  console.log(`== ${name}: ${report.passed.length} passed, ${report.failed.length} failed`);
  failed += report.failed.length;
  stopAll();
}
// The service goes away: onClose reports ConnectionError, pending and later calls reject with it.
if (!arg("--target") && !only) {
  const svc = start(arg("--interop-service"), ["--port", "0", "--websocket", "--max-lifetime", "300"]);
  const url = (await readyLine(svc, "ws_url")).ws_url;
  const c = await rr.connect(url, { timeoutMs: 5000 });
  const closed = new Promise((resolve) => c.$client.onClose(resolve));
  const pending = c.count_up(0, 3).then((g) => new Promise((r) => setTimeout(r, 300)).then(() => g.next()));
  svc.kill("SIGKILL");
  const err = await Promise.race([closed, new Promise((r) => setTimeout(() => r(null), 20000))]);
  const late = await c.add(1, 2).then(() => null, (e) => e);
  const pend = await pending.then(() => null, (e) => e);
  const okLost = err?.errorName === "RobotRaconteur.ConnectionError" && c.$client.state === "closed" &&
    late?.errorName === "RobotRaconteur.ConnectionError" && pend?.errorName === "RobotRaconteur.ConnectionError";
  console.log(`== service killed: onClose ${err?.errorName}, state ${c.$client.state}, call after ${late?.errorName}, ` +
    `pending ${pend?.errorName}: ${okLost ? "ok" : "FAIL"}`);
  if (!okLost) failed++;
}
console.log(failed ? `FAILED: ${failed} checks` : "all checks passed");
process.exit(failed ? 1 : 0);
