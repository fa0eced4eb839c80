// Runs api_checks.mjs with the BUILT package (wasm-client/dist) in node against three services:
//   1. rr_interop_service --websocket (our C++ service), rr+ws
//   2. rr-gateway in front of it (device over rr+tcp, client over rr+ws to the gateway), and in front of
//      the official service
//   3. the official Python service (test/interop/official_service.py), rr+ws on its TCP port
//   4. the official service with message format v2 only; 5. ours with v4 string tables;
//   6. ours behind nginx terminating TLS (rr+wss), when nginx and openssl are installed
//   7. the gateway serving TLS itself (rr+wss, its certificate given with the ca option; refused without;
//      trusted without the option by node processes told of it through NODE_EXTRA_CA_CERTS, or through
//      --use-openssl-ca with SSL_CERT_FILE, as docs/security.md "Browsers and the wasm client" says)
//
// Usage: node node_test.mjs --interop-service PATH --gateway PATH --python PATH [--only REGEX] [--target NAME]
// Exit: 0 all passed, 1 a check failed, 2 setup failed, 77 emscripten absent (package cannot be built) or,
// with nothing failed, a target skipped (nginx or openssl absent).
import { spawn, spawnSync } from "node:child_process";
import { existsSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from "node:fs";
import { createServer, connect as connectTcp } from "node:net";
import { tmpdir } from "node:os";
import { createInterface } from "node:readline";
import { fileURLToPath, pathToFileURL } from "node:url";
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

// rr-gateway with the service at `deviceUrl` as device "interop"; the rr+ws URL clients use. The device
// is in `auth: passthrough` mode (docs/security.md): the client gets its own session to the device, so
// the monitor lock check locks on the device itself (a shared device refuses locks).
// `moreConfig`: YAML put before the devices (e.g. a gateway: section). With gateway.tls the port still
// answers plain HTTP (tls.required is off), so the readiness check is the same.
async function behindGateway(deviceUrl, moreConfig = "") {
  const dir = mkdtempSync(join(tmpdir(), "rr-wasm-gw-"));
  process.on("exit", () => rmSync(dir, { recursive: true, force: true }));
  const config = join(dir, "gateway.yaml");
  writeFileSync(config, `${moreConfig}devices:\n  - name: interop\n    url: ${JSON.stringify(deviceUrl)}\n    auth: passthrough\n`);
  const gw = start(arg("--gateway"), ["--config", config, "--no-demo", "--no-local", "--listen", "127.0.0.1", "--port", "0",
    "--log-level", "warning"]);
  const { port } = await readyLine(gw, "port");
  await gatewayReady(port);
  return `rr+ws://127.0.0.1:${port}/?service=interop`;
}

/** A self-signed certificate for 127.0.0.1 in a fresh temporary folder (removed at exit). */
function selfSignedCertificate(prefix) {
  const tmp = mkdtempSync(join(tmpdir(), prefix));
  process.on("exit", () => rmSync(tmp, { recursive: true, force: true }));
  const cert = join(tmp, "cert.pem");
  const key = join(tmp, "key.pem");
  const gen = spawnSync("openssl", ["req", "-x509", "-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:prime256v1",
    "-nodes", "-days", "1", "-subj", "/CN=127.0.0.1", "-addext", "subjectAltName=IP:127.0.0.1", "-keyout", key,
    "-out", cert]);
  if (gen.status !== 0) throw new Error(`openssl: ${gen.stderr}`);
  return { tmp, cert, key };
}

const targets = {
  async ours() {
    const svc = start(arg("--interop-service"), ["--port", "0", "--websocket", "--max-lifetime", "300"]);
    return (await readyLine(svc, "ws_url")).ws_url;
  },
  async gateway() {
    const svc = start(arg("--interop-service"), ["--port", "0", "--max-lifetime", "300"]);
    return behindGateway((await readyLine(svc, "url")).url);
  },
  async "gateway-official"() {
    const py = arg("--python", join(root, ".venv", "bin", "python"));
    const svc = start(py, [join(root, "test", "interop", "official_service.py"), "--port", "0", "--max-lifetime", "300"]);
    return behindGateway((await readyLine(svc, "url")).url);
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
  // rr+wss: nginx terminates TLS (self-signed certificate for 127.0.0.1) in front of ours.
  async wss() {
    const nginx = ["/usr/sbin/nginx", "/usr/bin/nginx"].find((p) => existsSync(p));
    if (!nginx || spawnSync("sh", ["-c", "command -v openssl"]).status !== 0) return null;
    const svc = start(arg("--interop-service"), ["--port", "0", "--websocket", "--max-lifetime", "300"]);
    const { port } = await readyLine(svc, "ws_url");
    const { tmp, cert, key } = selfSignedCertificate("rr-wasm-wss-");
    const tlsPort = await freePort();
    writeFileSync(join(tmp, "nginx.conf"), `pid ${tmp}/nginx.pid; error_log ${tmp}/error.log;
events {}
http {
  access_log off; client_body_temp_path ${tmp}/body; proxy_temp_path ${tmp}/proxy;
  server {
    listen 127.0.0.1:${tlsPort} ssl;
    ssl_certificate ${cert}; ssl_certificate_key ${key};
    location / {
      proxy_pass http://127.0.0.1:${port}; proxy_http_version 1.1; proxy_read_timeout 300s;
      proxy_set_header Upgrade $http_upgrade; proxy_set_header Connection "upgrade";
    }
  }
}
`);
    start(nginx, ["-p", tmp, "-c", join(tmp, "nginx.conf"), "-g", "daemon off;"]);
    options.ca = readFileSync(cert);
    for (let i = 0; ; i++) {  // until nginx listens
      const up = await new Promise((resolve) => {
        const s = connectTcp(tlsPort, "127.0.0.1", () => resolve(true)).on("error", () => resolve(false));
        s.unref();
      });
      if (up) break;
      if (i > 300) throw new Error("nginx did not start in 30 s");
      await new Promise((r) => setTimeout(r, 100));
    }
    return `rr+wss://127.0.0.1:${tlsPort}/?service=interop`;
  },
  // rr+wss served by the gateway itself (gateway.tls), its certificate trusted through the ca option;
  // without that option node's own CA list refuses the self-signed certificate, and says so.
  async "gateway-wss"() {
    if (spawnSync("sh", ["-c", "command -v openssl"]).status !== 0) return null;
    const { cert, key } = selfSignedCertificate("rr-wasm-gwtls-");
    const svc = start(arg("--interop-service"), ["--port", "0", "--max-lifetime", "300"]);
    const url = await behindGateway((await readyLine(svc, "url")).url,
      `gateway:\n  tls:\n    certificate: ${JSON.stringify(cert)}\n    private_key: ${JSON.stringify(key)}\n`);
    const wssUrl = url.replace("rr+ws://", "rr+wss://");
    const refused = await rr.connect(wssUrl, { timeoutMs: 10000 }).then((c) => c.$client.close().then(() => null), (e) => e);
    if (!refused || refused.errorName !== "RobotRaconteur.ConnectionError" || !/certificate/i.test(refused.message)) {
      console.log(`  FAIL rr+wss without ca: expected a ConnectionError naming the certificate, got ${refused?.errorName}: ${refused?.message}`);
      failed++;
    } else {
      console.log(`  ok rr+wss without ca is refused: ${refused.message}`);
    }
    const misused = await rr.connect(url, { ca: readFileSync(cert) }).then(() => null, (e) => e);
    if (misused?.errorName !== "RobotRaconteur.InvalidArgument") {
      console.log(`  FAIL ca with an rr+ws URL: expected InvalidArgument, got ${misused?.errorName}: ${misused?.message}`);
      failed++;
    } else {
      console.log(`  ok ca with an rr+ws URL: ${misused.message}`);
    }
    // Trust from the process's CA store, no ca option: a fresh node per case, since node reads these
    // settings once at start. The refused cases show it is the setting, not the store, that trusts.
    const cases = [
      { name: "NODE_EXTRA_CA_CERTS=cert.pem", env: { NODE_EXTRA_CA_CERTS: cert }, ok: true },
      { name: "--use-openssl-ca with SSL_CERT_FILE=cert.pem", flags: ["--use-openssl-ca"], env: { SSL_CERT_FILE: cert }, ok: true },
      { name: "--use-openssl-ca (the system's store alone)", flags: ["--use-openssl-ca"], ok: false },
      { name: "SSL_CERT_FILE=cert.pem without --use-openssl-ca", env: { SSL_CERT_FILE: cert }, ok: false },
    ];
    for (const k of cases) {
      const got = await connectInFreshNode(wssUrl, k.flags ?? [], k.env ?? {});
      const pass = k.ok ? got.sum === 5 : got.error === "RobotRaconteur.ConnectionError" && /certificate/i.test(got.message);
      console.log(`  ${pass ? "ok" : "FAIL"} rr+wss without ca, ${k.name}: ${k.ok ? "expected add(2, 3) = 5" : "expected refused"}, got ${JSON.stringify(got)}`);
      if (!pass) failed++;
    }
    options.ca = readFileSync(cert, "utf8");
    return wssUrl;
  },
  async "ours-stringtable"() {
    const svc = start(arg("--interop-service"), ["--port", "0", "--websocket", "--enable-stringtable",
      "--max-lifetime", "300"]);
    return (await readyLine(svc, "ws_url")).ws_url;
  },
};

/** Connects to `url` (no ca option) in a new node process with `flags` and `env` on top of a CA-neutral
 * environment; resolves {sum} (add(2, 3)) or {error, message}. */
function connectInFreshNode(url, flags, env) {
  const script = `
const rr = await import(${JSON.stringify(pathToFileURL(dist).href)});
let out;
try {
  const c = await rr.connect(${JSON.stringify(url)}, { timeoutMs: 10000 });
  out = { sum: await c.add(2, 3) };
  await c.$client.close();
} catch (e) {
  out = { error: e.errorName ?? String(e), message: e.message };
}
console.log(JSON.stringify(out));
process.exit(0);
`;
  const base = { ...process.env };
  for (const k of ["NODE_EXTRA_CA_CERTS", "SSL_CERT_FILE", "SSL_CERT_DIR", "NODE_OPTIONS"]) delete base[k];
  return new Promise((resolve) => {
    const p = spawn(process.execPath, [...flags, "--input-type=module", "-e", script],
      { env: { ...base, ...env }, stdio: ["ignore", "pipe", "pipe"] });
    let out = "";
    let err = "";
    p.stdout.on("data", (d) => { out += d; });
    p.stderr.on("data", (d) => { err += d; });
    const timer = setTimeout(() => p.kill("SIGKILL"), 30000);
    p.on("exit", (code) => {
      clearTimeout(timer);
      try {
        resolve(JSON.parse(out.trim().split("\n").pop()));
      } catch {
        resolve({ error: `node exited with ${code}`, message: (out + err).slice(-500) });
      }
    });
  });
}

function freePort() {
  return new Promise((resolve) => {
    const srv = createServer().listen(0, "127.0.0.1", () => {
      const { port } = srv.address();
      srv.close(() => resolve(port));
    });
  });
}

const rr = await import(dist);
let options = {};
const { runChecks } = await import("./api_checks.mjs");
const only = arg("--only") ? new RegExp(arg("--only")) : null;
const chosen = arg("--target") ? [arg("--target")] : Object.keys(targets);
let failed = 0;
const skipped = [];
for (const name of chosen) {
  let url;
  try {
    url = await targets[name]();
  } catch (e) {
    console.error(`${name}: setup failed: ${e.message}`);
    stopAll();
    process.exit(2);
  }
  if (url === null) {
    console.log(`== ${name}: SKIP (nginx or openssl not installed)`);
    skipped.push(`${name}: nginx or openssl not installed (run scripts/setup.sh)`);
    continue;
  }
  console.log(`== ${name}: ${url}`);
  const report = await runChecks(rr, url, { log: (l) => console.log(`  ${l}`), only, options });
  options = {};
  console.log(`== ${name}: ${report.passed.length} passed, ${report.failed.length} failed`);
  failed += report.failed.length;
  stopAll();
}
// The service goes away: onClose reports ConnectionError, pending and later calls reject with it.
if (!arg("--target") && !only) {
  const svc = start(arg("--interop-service"), ["--port", "0", "--websocket", "--max-lifetime", "300"]);
  const url = (await readyLine(svc, "ws_url")).ws_url;
  const c = await rr.connect(url, { timeoutMs: 30000 });
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
// A target that could not run makes the whole test skipped (ctest: SKIP_RETURN_CODE 77), never passed;
// a failure elsewhere still fails it.
if (!failed && skipped.length) {
  for (const s of skipped) console.log(`SKIP: ${s}`);
  process.exit(77);
}
console.log(failed ? `FAILED: ${failed} checks` : "all checks passed");
process.exit(failed ? 1 : 0);
