// Processes and network pieces the reconnect tests control (node only): rr_interop_service and
// rr-gateway on fixed ports so that they can be restarted where clients look for them, and a TCP proxy
// that can cut the network silently (bytes dropped, sockets left open) or drop every connection.
import { spawn } from "node:child_process";
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from "node:fs";
import { createServer, connect as connectTcp } from "node:net";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { createInterface } from "node:readline";

export const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

/** Resolves once cond() holds, polled every 10 ms; throws after `timeoutMs` (a bound on a hang, not the
 *  expected time). */
export async function until(cond, what, timeoutMs = 30000) {
  const end = Date.now() + timeoutMs;
  while (!cond()) {
    if (Date.now() > end) throw new Error(`timed out waiting for ${what}`);
    await sleep(10);
  }
}

/** A test's checks: ok(cond, what) prints each and counts the failed ones (failed()). */
export function checks() {
  let failed = 0;
  return {
    ok(cond, what) {
      console.log(`  ${cond ? "ok  " : "FAIL"} ${what}`);
      if (!cond) failed++;
    },
    failed: () => failed,
  };
}

export function arg(name, fallback = null) {
  const i = process.argv.indexOf(name);
  return i > 0 && i + 1 < process.argv.length ? process.argv[i + 1] : fallback;
}

const children = new Set();
export function stopAll() {
  for (const p of children) if (p.exitCode === null && p.signalCode === null) p.kill("SIGKILL");
}
process.on("exit", stopAll);

/**
 * A free port below the ephemeral range: servers here are restarted on their port, and in between the
 * proxy's connection attempts to it take ephemeral local ports, which could otherwise be that very port.
 */
export async function freePort() {
  const low = Number(readFileSync("/proc/sys/net/ipv4/ip_local_port_range", "utf8").split(/\s+/)[0]) || 32768;
  const from = low > 29500 ? 29000 : 20000;
  for (let i = 0; i < 100; i++) {
    const port = from + Math.floor(Math.random() * (low - from));
    const free = await new Promise((resolve) => {
      const srv = createServer();
      srv.once("error", () => resolve(false));
      srv.listen(port, "127.0.0.1", () => srv.close(() => resolve(true)));
    });
    if (free) return port;
  }
  throw new Error("no free port below the ephemeral range");
}

/** Starts `cmd` and resolves with the process once it printed a JSON line holding `key`. */
function startReady(cmd, argv, key, timeoutMs = 30000) {
  const p = spawn(cmd, argv, { stdio: ["ignore", "pipe", "inherit"] });
  children.add(p);
  p.on("exit", () => children.delete(p));
  return new Promise((resolve, reject) => {
    const t = setTimeout(() => reject(new Error(`${cmd}: no ready line with "${key}" in ${timeoutMs} ms`)), timeoutMs);
    p.once("exit", (code) => reject(new Error(`${cmd} exited early with ${code}`)));
    createInterface({ input: p.stdout }).on("line", (line) => {
      try {
        const o = JSON.parse(line);
        if (key in o) {
          clearTimeout(t);
          resolve({ proc: p, ready: o });
        }
      } catch {
        // not the ready line
      }
    });
  });
}

/** Kills `proc` (SIGKILL: a crash, nothing said on the wire) and waits for its exit. */
export function kill(proc) {
  if (proc.exitCode !== null || proc.signalCode !== null) return Promise.resolve();
  return new Promise((resolve) => {
    proc.once("exit", () => resolve());
    proc.kill("SIGKILL");
  });
}

/** Binding a port a killed process held may fail for a moment: retry. */
async function retryStart(fn) {
  for (let i = 0; ; i++) {
    try {
      return await fn();
    } catch (e) {
      if (i >= 20) throw e;
      await sleep(100);
    }
  }
}

/** rr_interop_service on a fixed port (rr+tcp and rr+ws); restart() brings it back on the same port. */
export async function interopService(binary, port) {
  const s = {
    port,
    async start() {
      const { proc, ready } = await retryStart(() => startReady(binary, ["--port", String(port), "--websocket", "--max-lifetime", "300"], "ws_url"));
      s.proc = proc;
      s.tcpUrl = ready.url;
      s.wsUrl = ready.ws_url;
    },
    async restart(downMs = 300) {
      await kill(s.proc);
      await sleep(downMs);
      await s.start();
    },
  };
  await s.start();
  return s;
}

/** rr-gateway on a fixed port with device "interop" at `deviceUrl` (and `extraConfig`, YAML appended to
 *  its configuration file); restart() kills it and starts it again. */
export async function gateway(binary, port, deviceUrl, auth = "shared", extraConfig = "") {
  const dir = mkdtempSync(join(tmpdir(), "rr-wasm-reconnect-"));
  process.on("exit", () => rmSync(dir, { recursive: true, force: true }));
  const config = join(dir, "gateway.yaml");
  writeFileSync(config, `devices:\n  - name: interop\n    url: ${JSON.stringify(deviceUrl)}\n    auth: ${auth}\n${extraConfig}`);
  const g = {
    port,
    http: `http://127.0.0.1:${port}`,
    rrUrl: `rr+ws://127.0.0.1:${port}/?service=interop`,
    async start(webRoot) {
      if (webRoot) g.webRoot = webRoot;
      const extra = g.webRoot ? ["--web-root", g.webRoot] : [];
      const { proc } = await retryStart(() => startReady(binary, ["--config", config, "--no-demo", "--no-local", "--no-discovery",
        "--listen", "127.0.0.1", "--port", String(port), "--log-level", "error", ...extra], "port"));
      g.proc = proc;
      await g.deviceConnected();
    },
    async deviceConnected(timeoutMs = 20000) {
      const end = Date.now() + timeoutMs;
      for (;;) {
        const r = await fetch(`${g.http}/api/devices`).then((x) => x.json()).catch(() => null);
        if (r?.[0]?.state === "connected") return;
        if (Date.now() > end) throw new Error(`gateway device not connected: ${JSON.stringify(r)}`);
        await sleep(50);
      }
    },
    async restart(downMs = 300) {
      await kill(g.proc);
      await sleep(downMs);
      await g.start();
    },
  };
  return g;
}

/**
 * A TCP proxy on 127.0.0.1 to `target`: a port, or `(firstBytes: Buffer) => port` choosing per connection
 * from what the client sends first (e.g. WebSocket upgrades to one server, page loads to another).
 * cut(): from now on every byte either way is dropped and no socket is closed (a network that silently
 * loses packets), new connections included. restore(): forwards again for new connections (connections
 * open during the cut are ended: their streams have holes). dropAll(): ends every connection at once.
 */
export async function cutProxy(target) {
  const pairs = new Set();
  const state = { cut: false, accepted: 0 };
  const server = createServer((down) => {
    state.accepted++;
    const pair = { down, up: null, cut: state.cut };
    pairs.add(pair);
    const end = () => {
      pairs.delete(pair);
      down.destroy();
      pair.up?.destroy();
    };
    down.on("data", (d) => {
      if (pair.cut) return;
      if (!pair.up) {
        pair.up = connectTcp(typeof target === "function" ? target(d) : target, "127.0.0.1");
        pair.up.on("data", (x) => pair.cut || down.write(x));
        pair.up.on("error", end).on("close", end);
      }
      pair.up.write(d);
    });
    down.on("error", end).on("close", end);
  });
  await new Promise((r) => server.listen(0, "127.0.0.1", r));
  return {
    port: server.address().port,
    state,
    get connections() {
      return pairs.size;
    },
    cut() {
      state.cut = true;
      for (const p of pairs) p.cut = true;
    },
    restore() {
      state.cut = false;
      for (const p of [...pairs]) if (p.cut) {
        pairs.delete(p);
        p.down.destroy();
        p.up?.destroy();
      }
    },
    dropAll() {
      for (const p of [...pairs]) {
        pairs.delete(p);
        p.down.destroy();
        p.up?.destroy();
      }
    },
    close() {
      this.dropAll();
      server.close();
    },
  };
}
