// Processes for the browser tests: Reynard the Robot (test/interop/reynard_harness.py), rr-gateway
// with its demo devices and Reynard behind it, and headless Debian Chromium through playwright-core
// (web/node_modules, pinned in web/package.json). Every process is stopped by its PID.

import crypto from "node:crypto";
import fs from "node:fs";
import { spawn, spawnSync } from "node:child_process";
import { createRequire } from "node:module";
import { fileURLToPath } from "node:url";
import path from "node:path";
import readline from "node:readline";

export const ROOT = path.resolve(path.dirname(fileURLToPath(import.meta.url)), "../..");
/** require() that resolves in web/node_modules. */
export const webRequire = createRequire(path.join(ROOT, "web", "package.json"));

export const CHROMIUM_ARGS = ["--no-sandbox", "--disable-gpu", "--disable-background-networking",
  "--disable-component-update", "--disable-sync", "--no-first-run"];

/** Settings from the environment (test/browser/CMakeLists.txt sets them). */
export function settings() {
  const env = process.env;
  return {
    gateway: env.RR_GATEWAY,
    python: env.RR_PYTHON || path.join(ROOT, ".venv/bin/python"),
    webRoot: env.RR_WEB_ROOT || path.join(ROOT, "web/dist"),
    artifacts: env.RR_ARTIFACTS || path.join(ROOT, "build/test-artifacts/browser"),
  };
}

/** Where the threads of a live process are: gdb's backtraces (bounded), else each thread's wchan. */
function threadsOf(pid) {
  const gdb = spawnSync("gdb", ["-p", String(pid), "-batch", "-nx", "-ex", "thread apply all bt 25"],
    { encoding: "utf8", timeout: 30000 });
  if (gdb.status === 0 && /Thread /.test(gdb.stdout)) {
    return gdb.stdout.split("\n").filter((l) => /^(Thread |#)/.test(l)).join("\n").slice(0, 12000);
  }
  try {
    return fs.readdirSync(`/proc/${pid}/task`).map((t) => {
      const read = (f) => { try { return fs.readFileSync(`/proc/${pid}/task/${t}/${f}`, "utf8").trim(); } catch { return "?"; } };
      return `${t} ${read("comm")} ${read("wchan")}`;
    }).join("\n");
  } catch (e) {
    return `(no thread list: ${e.message})`;
  }
}

// Every child this test file started: when the file fails, the last of each one's stderr is printed
// as the process exits (after the after() hooks stopped them), so a failure under load can be read
// afterwards (docs/development.md "Tests that hold under load": on failure a test prints its logs).
const started = [];
process.on("exit", (code) => {
  if (!code && !process.exitCode) return;
  for (const c of started) {
    const tail = c.stderr.join("").slice(-4000);
    fs.writeSync(2, `\n--- ${c.name} (pid ${c.proc.pid}), the last of its stderr ---\n${tail || "(nothing)"}\n`);
  }
});

/** A child process whose stdout lines are read for a JSON object holding `key`. */
class Child {
  constructor(name, cmd, args, env = undefined, stdin = "ignore") {
    started.push(this);
    this.name = name;
    this.proc = spawn(cmd, args, { stdio: [stdin, "pipe", "pipe"], env });
    this.exited = new Promise((resolve) => this.proc.on("exit", (code, signal) => resolve({ code, signal })));
    this.lines = readline.createInterface({ input: this.proc.stdout });
    this.stderr = [];
    this.proc.stderr.on("data", (d) => {
      this.stderr.push(d.toString());
      if (this.stderr.length > 400) this.stderr.splice(0, 200);
      if (process.env.RR_BROWSER_VERBOSE) process.stderr.write(`[${name}] ${d}`);
    });
  }

  /** The first stdout line that is JSON with `key`; rejects on exit or after timeoutMs. */
  jsonLine(key, timeoutMs) {
    return new Promise((resolve, reject) => {
      const timer = setTimeout(() => done(new Error(`${this.name}: no JSON line with "${key}" within ${timeoutMs} ms\n${this.stderr.join("").slice(-3000)}`)), timeoutMs);
      const onLine = (line) => {
        try {
          const obj = JSON.parse(line);
          if (obj && key in obj) done(null, obj);
        } catch { /* not JSON */ }
      };
      const onExit = () => done(new Error(`${this.name} exited before its JSON line\n${this.stderr.join("").slice(-3000)}`));
      const done = (err, obj) => {
        clearTimeout(timer);
        this.lines.off("line", onLine);
        this.proc.off("exit", onExit);
        if (err) reject(err); else resolve(obj);
      };
      this.lines.on("line", onLine);
      this.proc.once("exit", onExit);
    });
  }

  /**
   * SIGTERM, then SIGKILL after graceMs. Resolves with the exit status ({code, signal}); when SIGKILL
   * was needed it also has `stuck`: where the process's threads were (gdb backtraces, else each
   * thread's wchan) and its last stderr, so a shutdown hang names itself in the test's failure.
   */
  async stop(graceMs = 20000) {  // an ASan gateway beside a loaded CI run took over 10 s to exit
    if (this.proc.exitCode !== null || this.proc.signalCode !== null) return this.exited;
    this.proc.kill("SIGTERM");
    let stuck = null;
    const timer = setTimeout(() => {
      stuck = `${threadsOf(this.proc.pid)}\n--- last stderr ---\n${this.stderr.join("").slice(-2000)}`;
      this.proc.kill("SIGKILL");
    }, graceMs);
    const status = await this.exited;
    clearTimeout(timer);
    return stuck ? { ...status, stuck } : status;
  }
}

/**
 * Starts `cmd args` and resolves { child, info } with its first stdout line that is JSON holding
 * `key` (within timeoutMs). `options.stdin`: "pipe" to write to child.proc.stdin (default "ignore").
 * child.jsonLine(key, ms) reads later lines the same way; child.stop() ends it by its PID.
 */
export async function startProcess(name, cmd, args, key = "url", timeoutMs = 60000, options = {}) {
  const child = new Child(name, cmd, args, options.env, options.stdin ?? "ignore");
  const info = await child.jsonLine(key, timeoutMs);
  return { child, info };
}

/** Starts Reynard headless (rrPort 0 = ephemeral). Resolves { child, info } with the harness's JSON line. */
export async function startReynard(s, rrPort = 0) {
  const child = new Child("reynard", s.python, [path.join(ROOT, "test/interop/reynard_harness.py"),
    "--rr-port", String(rrPort), "--max-lifetime", "600", "--start-timeout", "40"]);
  const info = await child.jsonLine("url", 60000);
  return { child, info };
}

/**
 * Starts rr-gateway on 127.0.0.1 (port 0 = ephemeral), demo devices on, plus `devices` {name: url}
 * and `extraArgs` (e.g. ["--allow-origin", ORIGIN]). `options.local`: publish the node on rr+local
 * (default false: --no-local); `options.env`: the process environment (e.g. node directories).
 */
export async function startGateway(s, devices = {}, listenPort = 0, extraArgs = [], options = {}) {
  const args = ["--listen", "127.0.0.1", "--port", String(listenPort), "--web-root", s.webRoot, "--log-level", "warning",
    ...(options.local ? [] : ["--no-local"]), ...extraArgs];
  for (const [name, url] of Object.entries(devices)) args.push("--device", `${name}=${url}`);
  const child = new Child("rr-gateway", s.gateway, args, options.env);
  const { port } = await child.jsonLine("port", 30000);
  return { child, port, base: `http://127.0.0.1:${port}` };
}

/**
 * Writes a gateway configuration with logins into folder `dir`: users alice (password alice-pw, role
 * operator: read, write, call and lock everything, record every device, and objectlock) and bob (bob-pw, role viewer: read only),
 * then the YAML lines `rest` (devices:, demo:, ...). Returns the configuration file's path.
 */
export function writeOperatorViewerConfig(dir, rest) {
  const md5 = (t) => crypto.createHash("md5").update(t).digest("hex");
  const users = path.join(dir, "users.txt");
  fs.writeFileSync(users, `alice ${md5("alice-pw")} operator,objectlock\nbob ${md5("bob-pw")} viewer\n`, { mode: 0o600 });
  const config = path.join(dir, "gateway.yaml");
  fs.writeFileSync(config, [
    "gateway:",
    "  auth:",
    `    users: ${users}`,
    "    roles:",
    "      operator:",
    "        - allow: [read, write, call, lock, record]",
    "      viewer:",
    "        - devices: \"*\"",
    "          members: \"*\"",
    "          allow: [read]",
    ...rest,
    "",
  ].join("\n"));
  return config;
}

/** Polls `fn` until it returns a truthy value; rejects with `what` after timeoutMs. */
export async function waitFor(fn, what, timeoutMs = 20000, everyMs = 100) {
  const deadline = Date.now() + timeoutMs;
  let last;
  for (;;) {
    try {
      const v = await fn();
      if (v) return v;
    } catch (e) {
      last = e;
    }
    if (Date.now() > deadline) throw new Error(`timed out waiting for ${what}${last ? `: ${last.message}` : ""}`);
    await new Promise((r) => setTimeout(r, everyMs));
  }
}

/** GET /api/devices of the gateway (no Origin header: not a browser). */
export async function apiDevices(base) {
  const r = await fetch(`${base}/api/devices`);
  if (!r.ok) throw new Error(`GET /api/devices: ${r.status}`);
  return r.json();
}

/** Headless Debian Chromium. */
export async function launchChromium() {
  const { chromium } = webRequire("playwright-core");
  return chromium.launch({ executablePath: "/usr/bin/chromium", headless: true, args: CHROMIUM_ARGS });
}

/**
 * A TCP relay in front of a device: the gateway is configured with the relay's port, so the test can
 * make the device drop (close every connection and stop listening) and come back (listen again on
 * the same port) without restarting the device, whose own port could still be held in TIME_WAIT.
 */
export class TcpRelay {
  constructor(targetPort, targetHost = "127.0.0.1") {
    this.target = { port: targetPort, host: targetHost };
    this.sockets = new Set();
    this.port = 0;
  }

  async listen() {
    const net = await import("node:net");
    this.server = net.createServer((client) => {
      const upstream = net.connect(this.target);
      for (const s of [client, upstream]) {
        this.sockets.add(s);
        s.on("close", () => this.sockets.delete(s));
        s.on("error", () => {});
      }
      client.pipe(upstream);
      upstream.pipe(client);
      client.on("close", () => upstream.destroy());
      upstream.on("close", () => client.destroy());
    });
    await new Promise((resolve, reject) => {
      this.server.once("error", reject);
      this.server.listen(this.port, "127.0.0.1", resolve);
    });
    this.port = this.server.address().port;
    return this.port;
  }

  /** Drops every connection and refuses new ones until listen() again. */
  async drop() {
    const closed = new Promise((resolve) => this.server.close(resolve));
    for (const s of this.sockets) s.destroy();
    await closed;
  }
}
