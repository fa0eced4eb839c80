// A device with members named `then` (experimental.thenable.robdef, served by the official Python
// library: then_service.py) reached with the BUILT package (wasm-client/dist) in node, straight over
// rr+ws and through rr-gateway: a proxy must never be a thenable (with a `then` function property,
// `await connect()` and an objref's `get()` would call it and never resolve), and the members named
// `then` are reached with $member("then") (README "API").
//
// Usage: node thenable_test.mjs --gateway PATH --python PATH
// Exit: 0 all passed, 1 a check failed, 2 setup failed, 77 wasm-client/dist missing and emscripten absent.
import { spawn, spawnSync } from "node:child_process";
import { existsSync, mkdtempSync, rmSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { createInterface } from "node:readline";
import { fileURLToPath, pathToFileURL } from "node:url";
import { dirname, join } from "node:path";

const here = dirname(fileURLToPath(import.meta.url));
const root = join(here, "..", "..", "..");
const dist = join(here, "..", "..", "dist", "robotraconteur.mjs");

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
process.on("exit", () => {
  for (const p of children) if (p.exitCode === null && p.signalCode === null) p.kill("SIGTERM");
});

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

/** `promise`, or a rejection naming `what` after `ms` (a bound on a hang: the awaited proxy never resolved). */
function bounded(promise, what, ms = 20000) {
  let t;
  const timeout = new Promise((_, reject) => { t = setTimeout(() => reject(new Error(`${what}: no answer in ${ms} ms`)), ms); });
  return Promise.race([promise, timeout]).finally(() => clearTimeout(t));
}

let failed = 0;
async function check(name, fn) {
  try {
    await fn();
    console.log(`  ok ${name}`);
  } catch (e) {
    failed++;
    console.log(`  FAIL ${name}: ${e?.errorName ?? ""} ${e?.message ?? e}`);
  }
}
function expect(cond, what) {
  if (!cond) throw new Error(what);
}

async function gatewayUrl(deviceUrl) {
  const dir = mkdtempSync(join(tmpdir(), "rr-wasm-then-"));
  process.on("exit", () => rmSync(dir, { recursive: true, force: true }));
  const config = join(dir, "gateway.yaml");
  writeFileSync(config, `devices:\n  - name: thenable\n    url: ${JSON.stringify(deviceUrl)}\n`);
  const gw = start(arg("--gateway"), ["--config", config, "--no-demo", "--no-local", "--listen", "127.0.0.1", "--port", "0",
    "--log-level", "warning"]);
  const { port } = await readyLine(gw, "port");
  const end = Date.now() + 30000;
  for (;;) {  // until the device is connected (its definitions are known)
    try {
      const r = await fetch(`http://127.0.0.1:${port}/api/devices/thenable`);
      if (r.ok && (await r.json()).state === "connected") break;
    } catch {
      // not listening yet
    }
    if (Date.now() > end) throw new Error("the gateway did not connect the device");
    await new Promise((r) => setTimeout(r, 100));
  }
  return `rr+ws://127.0.0.1:${port}/?service=thenable`;
}

async function checks(rr, url, where) {
  console.log(where);
  let p = null;
  await check("await connect() resolves with the proxy (it is no thenable)", async () => {
    p = await bounded(rr.connect(url, { timeoutMs: 15000 }), "connect");
    expect(p.$type === "experimental.thenable.Root", `$type ${p.$type}`);
    expect(!("then" in p), "the proxy has a then property");
    expect((await bounded(Promise.resolve(p), "a promise resolved with the proxy")) === p, "awaiting the proxy gave something else");
  });
  if (!p) return;
  try {
    await check('$member("then") is the function member; other members stay properties', async () => {
      expect(p.$members.some((m) => m.name === "then" && m.kind === "function"), "then is listed in $members");
      expect((await p.$member("then")(41)) === 42, "then(41) is 42");
      expect((await p.value.get()) === 7, "value is 7");
      expect(p.$member("value") === p.value, "$member gives the same member object as the property");
    });
    await check("an objref's get() resolves with a proxy whose property `then` is reached with $member", async () => {
      const c = await bounded(p.child.get(), "child.get()");
      expect(c.$type === "experimental.thenable.Child", `$type ${c.$type}`);
      expect(!("then" in c), "the child proxy has a then property");
      expect((await c.$member("then").get()) === "child then", "child's then property");
    });
    await check("$member of a name the object does not have: RRError MemberNotFound", async () => {
      let error = null;
      try {
        p.$member("nosuch");
      } catch (e) {
        error = e;
      }
      expect(error?.errorName === "RobotRaconteur.MemberNotFound", `got ${error?.errorName}: ${error?.message}`);
      expect(/no member "nosuch"/.test(error.message), error.message);
    });
  } finally {
    await p.$client.close();
  }
}

try {
  const rr = await import(pathToFileURL(dist).href);
  const py = arg("--python", join(root, ".venv", "bin", "python"));
  const svc = start(py, [join(here, "then_service.py"), "--max-lifetime", "300"]);
  const ready = await readyLine(svc, "ws_url");
  await checks(rr, ready.ws_url, "official service, rr+ws:");
  if (arg("--gateway")) await checks(rr, await gatewayUrl(ready.url), "through rr-gateway, rr+ws:");
} catch (e) {
  console.error(`setup failed: ${e?.stack ?? e}`);
  process.exit(2);
}
console.log(failed ? `${failed} check(s) failed` : "all passed");
process.exit(failed ? 1 : 0);
