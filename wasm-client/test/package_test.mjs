// The client package as a user gets it: `npm pack` of wasm-client/dist gives a tarball holding every
// file package.json lists; `npm install` of that tarball into an empty project works offline; index.d.ts
// type-checks typecheck/usage.ts (tsc --noEmit, strict) and rejects every line of typecheck/misuse.ts;
// the compiled usage.ts then runs against rr-gateway's demo devices (every member kind, errors); without
// a WebSocket implementation connect() rejects with an RRError naming `ws`; the package's rr-robdef
// command generates types from the running demo devices (--url, --gateway/--device, --definitions -).
// Usage: node package_test.mjs --gateway PATH. Exit 77 (skipped) when dist/ or typescript is missing.
import { execFileSync, spawn, spawnSync } from "node:child_process";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";
import readline from "node:readline";
import { fileURLToPath } from "node:url";

const here = path.dirname(fileURLToPath(import.meta.url));
const pkgRoot = path.resolve(here, "..");
const dist = path.join(pkgRoot, "dist");
const tsc = path.join(pkgRoot, "node_modules/typescript/bin/tsc");
const arg = (name) => { const i = process.argv.indexOf(name); return i > 0 ? process.argv[i + 1] : undefined; };
const gatewayBin = arg("--gateway");

function skip(why) { console.log(`SKIP: ${why}`); process.exit(77); }
if (!fs.existsSync(path.join(dist, "robotraconteur_wasm.wasm"))) skip("wasm-client/dist not built (wasm-client/build.sh)");
if (!fs.existsSync(tsc)) skip("typescript missing (npm ci in wasm-client/, scripts/setup.sh)");
if (!gatewayBin) { console.error("usage: package_test.mjs --gateway PATH"); process.exit(2); }

let failures = 0;
const ok = (cond, what) => { console.log(`${cond ? "ok" : "FAIL"}: ${what}`); if (!cond) failures++; };
const run = (cmd, args, opts = {}) => execFileSync(cmd, args, { encoding: "utf8", stdio: ["ignore", "pipe", "pipe"], ...opts });

const tmp = fs.mkdtempSync(path.join(os.tmpdir(), "rr-wasm-pack-"));
let gateway;
try {
  // npm pack: a tarball with every file of package.json "files"
  const packed = JSON.parse(run("npm", ["pack", dist, "--pack-destination", tmp, "--json"], { cwd: tmp }))[0];
  const listed = new Set(packed.files.map((f) => f.path));
  const wanted = JSON.parse(fs.readFileSync(path.join(dist, "package.json"), "utf8")).files;
  const holds = (f) => (f.endsWith("/") ? [...listed].some((p) => p.startsWith(f)) : listed.has(f));
  ok(wanted.every(holds), `npm pack: ${packed.filename} holds ${wanted.join(", ")} (${packed.size} bytes)`);

  // an empty project installs the tarball (offline: nothing comes from a registry)
  const app = path.join(tmp, "app");
  fs.mkdirSync(app);
  fs.writeFileSync(path.join(app, "package.json"), JSON.stringify({ name: "usage-app", private: true, type: "module" }));
  run("npm", ["install", "--offline", "--no-audit", "--no-fund", "--no-package-lock", path.join(tmp, packed.filename)], { cwd: app });
  const installed = path.join(app, "node_modules/robotraconteur-wasm");
  ok(fs.existsSync(path.join(installed, "robotraconteur_wasm.wasm")) && fs.existsSync(path.join(installed, "index.d.ts")),
    "npm install of the tarball");
  // the standard types (the dashboard's web/src/std) import from "robotraconteur-wasm/std"
  fs.writeFileSync(path.join(app, "std_check.mjs"), [
    'import { RobdefOutline, standardDescriber, typedText, decodeImage, imageToBitmap, formatUuid, FrameDecoder } from "robotraconteur-wasm/std";',
    'const outline = new RobdefOutline({ "t.s": "service t.s\\nstruct P\\n    field double x\\nend\\n" });',
    'const d = standardDescriber(outline).describe("P", "t.s");',
    'const img = decodeImage({ image_info: { width: 1, height: 1, step: 3, encoding: 0x1002 }, data: Uint8Array.of(1, 2, 3) });',
    'const ok = typedText({ x: 1.5 }, d) === "{x: 1.5}" && img.ok && Array.from(img.data).join() === "3,2,1,255"',
    '  && formatUuid({ uuid_bytes: new Uint8Array(16).fill(255) }) === "ffffffff-ffff-ffff-ffff-ffffffffffff"',
    '  && typeof imageToBitmap === "function" && typeof FrameDecoder === "function";',
    'console.log(ok ? "std: ok" : "std: wrong");',
  ].join("\n"));
  const std = run(process.execPath, [path.join(app, "std_check.mjs")], { cwd: app });
  ok(/std: ok/.test(std), `import from "robotraconteur-wasm/std" (standard types): ${std.trim()}`);
  // the robot modules (web/src/robot) import from "robotraconteur-wasm/robot/<module>.js"; kinematics runs in node
  fs.writeFileSync(path.join(app, "robot_check.mjs"), [
    'import { chainModel, forwardKinematics } from "robotraconteur-wasm/robot/kinematics.js";',
    'const info = { joint_info: [{ joint_type: 1 }, { joint_type: 3 }], chains: [{ H: [{ x: 0, y: 0, z: 1 }, { x: 1, y: 0, z: 0 }],',
    '  P: [{ x: 0, y: 0, z: 0.5 }, { x: 0.3, y: 0, z: 0 }, { x: 0, y: 0, z: 0 }], joint_numbers: Uint32Array.of(0, 1) }] };',
    'const { position: p } = forwardKinematics(chainModel(info), [Math.PI / 2, 0.2]).tcp;',
    'console.log(Math.abs(p.x) < 1e-12 && Math.abs(p.y - 0.5) < 1e-12 && Math.abs(p.z - 0.5) < 1e-12 ? "robot: ok" : `robot: wrong ${JSON.stringify(p)}`);',
  ].join("\n"));
  const robotOut = run(process.execPath, [path.join(app, "robot_check.mjs")], { cwd: app });
  ok(/robot: ok/.test(robotOut), `import from "robotraconteur-wasm/robot/kinematics.js" (forward kinematics): ${robotOut.trim()}`);
  ok(fs.existsSync(path.join(installed, "dashboard/robot/view3d.js")) && fs.existsSync(path.join(installed, "dashboard/robot/view3d.d.ts")),
    "the package holds dashboard/robot/view3d.js and its declarations");
  // without a WebSocket implementation (no global one, no ws package) connect() rejects with an RRError
  // that says what to install
  fs.writeFileSync(path.join(app, "no_ws_check.mjs"), [
    'import { connect, RRError } from "robotraconteur-wasm";',
    "delete globalThis.WebSocket;",
    'try { await connect("rr+ws://127.0.0.1:9/?service=x"); console.log("no_ws: connected?"); }',
    'catch (e) { console.log(e instanceof RRError && e.errorName === "RobotRaconteur.InvalidOperation" && /npm install ws/.test(e.message) ? `no_ws: ok ${e.message}` : `no_ws: wrong ${e?.constructor?.name} ${e?.errorName} ${e?.message}`); }',
  ].join("\n"));
  const noWs = run(process.execPath, [path.join(app, "no_ws_check.mjs")], { cwd: app }).trim();
  ok(/^no_ws: ok/.test(noWs), `connect() without ws: an RRError naming the package (${noWs})`);
  // ws (the optional peer dependency for node) from this folder's node_modules
  fs.symlinkSync(path.join(pkgRoot, "node_modules/ws"), path.join(app, "node_modules/ws"), "dir");

  for (const f of ["usage.ts", "std_usage.ts", "robot_usage.ts", "subscription_usage.ts", "misuse.ts", "ws.d.ts", "tsconfig.json"]) fs.copyFileSync(path.join(here, "typecheck", f), path.join(app, f));
  // tsc --noEmit: usage.ts is accepted
  try {
    run(process.execPath, [tsc, "--noEmit", "-p", app]);
    ok(true, "tsc --noEmit (strict): usage.ts, std_usage.ts, robot_usage.ts and subscription_usage.ts type-check against index.d.ts, std/index.d.ts and robot/*.d.ts");
  } catch (e) {
    ok(false, `tsc --noEmit usage.ts:\n${e.stdout}${e.stderr}`);
  }
  // every MISUSE line of misuse.ts is an error
  let out = "";
  try {
    run(process.execPath, [tsc, "--noEmit", "--strict", "--module", "NodeNext", "--moduleResolution", "NodeNext", "--target", "ES2022",
      "misuse.ts"], { cwd: app });
  } catch (e) { out = e.stdout + e.stderr; }
  const lines = fs.readFileSync(path.join(app, "misuse.ts"), "utf8").split("\n");
  const misuse = lines.map((l, i) => (l.includes("// MISUSE") ? i + 1 : 0)).filter(Boolean);
  const reported = misuse.filter((n) => new RegExp(`misuse\\.ts\\(${n},`).test(out));
  ok(misuse.length === 5 && reported.length === misuse.length,
    `tsc rejects misuse.ts lines ${misuse.join(", ")} (reported: ${reported.join(", ") || "none"})`);

  // compile usage.ts and run it against the gateway's demo devices
  run(process.execPath, [tsc, "-p", app]);
  gateway = spawn(gatewayBin, ["--listen", "127.0.0.1", "--port", "0", "--no-local", "--log-level", "warning"], { stdio: ["ignore", "pipe", "pipe"] });
  gateway.stderr.on("data", (d) => process.stderr.write(`[rr-gateway] ${d}`));
  const port = await new Promise((resolve, reject) => {
    const rl = readline.createInterface({ input: gateway.stdout });
    rl.on("line", (l) => { try { const j = JSON.parse(l); if (j.port) resolve(j.port); } catch { /* not JSON */ } });
    gateway.once("exit", () => reject(new Error("rr-gateway exited")));
    setTimeout(() => reject(new Error("rr-gateway: no port line")), 30000);
  });
  // the demo devices connect to the gateway in the background: wait for both
  for (let i = 0; ; i++) {
    const devices = await (await fetch(`http://127.0.0.1:${port}/api/devices`)).json();
    if (devices.filter((d) => d.state === "connected").length >= 2) break;
    if (i > 200) throw new Error(`devices not connected: ${JSON.stringify(devices)}`);
    await new Promise((r) => setTimeout(r, 100));
  }
  // the package's rr-robdef command (node_modules/.bin, as npx runs it): a running device's definitions
  // by rr+ws, through the gateway's JSON API, and from that API's answer on stdin
  const rrRobdef = path.join(app, "node_modules/.bin/rr-robdef");
  const definitionsJson = await (await fetch(`http://127.0.0.1:${port}/api/devices/webcam/definitions`)).text();
  for (const [how, args, input] of [
    ["--url", ["--url", `rr+ws://127.0.0.1:${port}/?service=create`], undefined],
    ["--gateway --device", ["--gateway", `http://127.0.0.1:${port}`, "--device", "webcam"], undefined],
    ["--definitions -", ["--definitions", "-"], definitionsJson],
  ]) {
    const out = path.join(app, "gen", how.replace(/[^a-z]+/g, "_"));
    try {
      run(rrRobdef, ["ts", "-o", out, ...args], { cwd: app, input, stdio: ["pipe", "pipe", "pipe"] });
      const files = fs.readdirSync(out).sort();
      const want = how === "--url" ? "experimental.create.ts" : "experimental.createwebcam.ts";
      ok(files.includes(want) && /export interface/.test(fs.readFileSync(path.join(out, want), "utf8")),
        `npx rr-robdef ts ${how}: ${files.join(", ")}`);
    } catch (e) {
      ok(false, `npx rr-robdef ts ${how}:\n${e.stdout ?? ""}${e.stderr ?? ""}`);
    }
  }
  {
    const r = spawnSync(rrRobdef, ["ts", "--gateway", `http://127.0.0.1:${port}`, "--device", "nope", "-o", path.join(app, "gen/none")], { encoding: "utf8" });
    ok(r.status === 1 && /HTTP 404/.test(r.stderr) && !fs.existsSync(path.join(app, "gen/none")),
      `npx rr-robdef ts --device of no device: exit ${r.status}, "${r.stderr.trim().split("\n")[0]}"`);
  }
  try {
    const r = run(process.execPath, [path.join(app, "out/usage.js"), `rr+ws://127.0.0.1:${port}/`], { cwd: app, timeout: 120000 });
    process.stdout.write(`${r.trimEnd().replace(/^/gm, "  | ")}\n`);
    ok(/usage: all ok/.test(r), "usage.js ran every member kind against the demo devices");
  } catch (e) {
    ok(false, `usage.js failed:\n${e.stdout}${e.stderr}`);
  }
} catch (e) {
  ok(false, `${e.message}\n${e.stdout ?? ""}${e.stderr ?? ""}`);
} finally {
  if (gateway && gateway.exitCode === null) {
    gateway.kill("SIGTERM");
    await new Promise((r) => gateway.once("exit", r));
  }
  fs.rmSync(tmp, { recursive: true, force: true });
}
console.log(failures ? `${failures} failure(s)` : "all passed");
process.exit(failures ? 1 : 0);
