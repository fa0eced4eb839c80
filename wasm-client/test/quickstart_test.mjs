// README.md "TypeScript quickstart", run as written: its marked blocks are read from the README (so the
// README cannot drift from what is tested) and run in a temporary folder holding the packed tarball:
//   <!-- quickstart: sh -->            the shell lines, in order, in one bash (set -e; `cd` carries on)
//   <!-- quickstart: file PATH -->     the block's text written to PATH (relative to the shell's folder)
//   <!-- quickstart: run -->           the program, started by the test in the shell's last folder
// against a demo rr-gateway (its port put where the README says 127.0.0.1:8080). The packages come
// from the npm registry (TypeScript as it is current there), the package from `npm pack` of dist/.
// Then the program's story is checked, each step by waiting for its line (bounds only against hangs):
// `connected (1)`, the distance, packets; the gateway stopped (SIGTERM) and started again on the same
// port: `lost: …1001…`, `connected (2)`, packets again (its onConnect asked for them again); Ctrl-C
// (SIGINT): `closed` and exit 0. Finally tsc, as the app runs it, rejects a misspelled wire, event,
// objref path and a wire value used as a string.
// Usage: node quickstart_test.mjs --gateway PATH. Exit 77 (skipped) when dist/ is missing or the npm
// registry is unreachable.
import { execFileSync, spawn, spawnSync } from "node:child_process";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";
import readline from "node:readline";
import { fileURLToPath } from "node:url";

const here = path.dirname(fileURLToPath(import.meta.url));
const pkgRoot = path.resolve(here, "..");
const dist = path.join(pkgRoot, "dist");
const readme = path.join(pkgRoot, "README.md");
const arg = (name) => { const i = process.argv.indexOf(name); return i > 0 ? process.argv[i + 1] : undefined; };
const gatewayBin = arg("--gateway");
const HANG_BOUND_MS = 120000;  // any one step: only against a hang (CI load makes steps slow, not wrong)

function skip(why) { console.log(`SKIP: ${why}`); process.exit(77); }
if (!gatewayBin) { console.error("usage: quickstart_test.mjs --gateway PATH"); process.exit(2); }
if (!fs.existsSync(path.join(dist, "robotraconteur_wasm.wasm"))) skip("wasm-client/dist not built (wasm-client/build.sh)");
if (!fs.existsSync(path.join(dist, "rr_robdef_node.wasm"))) skip("wasm-client/dist has no rr-robdef (wasm-client/build.sh)");
{
  const r = spawnSync("npm", ["view", "typescript", "version"], { encoding: "utf8", timeout: 60000 });
  if (r.status !== 0) skip(`the npm registry is unreachable (npm view typescript: ${(r.stderr || r.error?.message || "").trim().split("\n")[0]})`);
  console.log(`the registry's TypeScript: ${r.stdout.trim()}`);
}

let failures = 0;
const ok = (cond, what) => { console.log(`${cond ? "ok" : "FAIL"}: ${what}`); if (!cond) failures++; };
const children = new Set();
process.on("exit", () => { for (const p of children) if (p.exitCode === null && p.signalCode === null) p.kill("SIGKILL"); });

/** The quickstart's steps: [{kind: "sh" | "file" | "run", path?, text}] in README order. */
function quickstartSteps() {
  const text = fs.readFileSync(readme, "utf8");
  const start = text.indexOf("## TypeScript quickstart");
  if (start < 0) throw new Error("README.md has no \"## TypeScript quickstart\" section");
  const end = text.indexOf("\n## ", start + 5);
  const section = text.slice(start, end < 0 ? undefined : end);
  const steps = [];
  for (const m of section.matchAll(/<!-- quickstart: (sh|run|file ([^ ]+)) -->\n```[a-z]*\n([\s\S]*?)\n```/g))
    steps.push({ kind: m[1].split(" ")[0], path: m[2], text: m[3] + "\n" });
  return steps;
}

/** Starts rr-gateway (demo devices) on `port` (0: any); resolves with its port once both demo devices are connected. */
async function startGateway(port) {
  const p = spawn(gatewayBin, ["--listen", "127.0.0.1", "--port", String(port), "--no-local", "--no-discovery", "--log-level", "warning"],
    { stdio: ["ignore", "pipe", "inherit"] });
  children.add(p);
  const ready = await new Promise((resolve, reject) => {
    const t = setTimeout(() => reject(new Error("rr-gateway: no ready line")), HANG_BOUND_MS);
    p.once("exit", (code) => { clearTimeout(t); reject(new Error(`rr-gateway exited early (${code})`)); });
    readline.createInterface({ input: p.stdout }).on("line", (l) => {
      try { const o = JSON.parse(l); if (o.port) { clearTimeout(t); resolve(o.port); } } catch { /* a log line */ }
    });
  });
  for (const deadline = Date.now() + HANG_BOUND_MS; ;) {
    const devices = await (await fetch(`http://127.0.0.1:${ready}/api/devices`)).json();
    if (devices.filter((d) => d.state === "connected").length >= 2) break;
    if (Date.now() > deadline) throw new Error(`demo devices not connected: ${JSON.stringify(devices)}`);
    await new Promise((r) => setTimeout(r, 100));
  }
  return { process: p, port: ready };
}

async function stopGateway(g) {
  if (g.process.exitCode !== null || g.process.signalCode !== null) return;
  const exited = new Promise((r) => g.process.once("exit", (code, signal) => r(code ?? signal)));
  g.process.kill("SIGTERM");
  const status = await Promise.race([exited, new Promise((r) => setTimeout(() => r("hung"), HANG_BOUND_MS))]);
  if (status === "hung") g.process.kill("SIGKILL");
  return status;
}

/** The program's output, line by line; waitFor(re) resolves with the first line at or after `from` that matches. */
function lines(p) {
  const all = [];
  const waiters = new Set();
  readline.createInterface({ input: p.stdout }).on("line", (l) => {
    all.push(l);
    process.stdout.write(`  | ${l}\n`);
    for (const w of waiters) w();
  });
  return {
    all,
    waitFor(re, from = 0, what = String(re)) {
      return new Promise((resolve, reject) => {
        const t = setTimeout(() => { waiters.delete(check); reject(new Error(`no line matching ${what} within ${HANG_BOUND_MS} ms`)); }, HANG_BOUND_MS);
        const check = () => {
          const i = all.findIndex((l, k) => k >= from && re.test(l));
          if (i >= 0) { clearTimeout(t); waiters.delete(check); resolve(i); }
        };
        waiters.add(check);
        check();
      });
    },
  };
}

const tmp = fs.mkdtempSync(path.join(os.tmpdir(), "rr-quickstart-"));
let gateway;
try {
  const steps = quickstartSteps();
  const runs = steps.filter((s) => s.kind === "run");
  ok(steps.length >= 4 && runs.length === 1 && steps.at(-1).kind === "run",
    `README quickstart: ${steps.map((s) => s.kind + (s.path ? ` ${s.path}` : "")).join(", ")}`);

  // the tarball the README installs, packed where its commands expect it (the folder they start in)
  const packed = JSON.parse(execFileSync("npm", ["pack", dist, "--pack-destination", tmp, "--json"], { cwd: tmp, encoding: "utf8" }))[0];
  const named = /npm install \.\.\/(robotraconteur-wasm-[^ ]+\.tgz)/.exec(steps.map((s) => s.text).join(""))?.[1];
  ok(named === packed.filename, `the README installs ${named}, npm pack gives ${packed.filename} (${(packed.size / 1024).toFixed(0)} KiB)`);

  gateway = await startGateway(0);
  const port = gateway.port;
  const local = (t) => t.replaceAll("127.0.0.1:8080", `127.0.0.1:${port}`);

  // the shell steps and files, as one bash script: `cd` in one block holds for the next
  const cwdFile = path.join(tmp, ".quickstart-cwd");
  let script = "set -euo pipefail\n";
  for (const s of steps) {
    if (s.kind === "sh") script += local(s.text);
    else if (s.kind === "file") script += `mkdir -p "$(dirname '${s.path}')"\ncat > '${s.path}' <<'__RR_QUICKSTART_FILE__'\n${local(s.text)}__RR_QUICKSTART_FILE__\n`;
  }
  script += `pwd > '${cwdFile}'\n`;
  const env = { ...process.env, npm_config_audit: "false", npm_config_fund: "false", npm_config_update_notifier: "false", npm_config_yes: "true" };
  const sh = spawnSync("bash", ["-c", script], { cwd: tmp, env, encoding: "utf8", timeout: 15 * 60000 });
  process.stdout.write(`${(sh.stdout + sh.stderr).trimEnd().replace(/^/gm, "  $ ")}\n`);
  ok(sh.status === 0, `the quickstart's commands run (exit ${sh.status ?? sh.error?.message})`);
  if (sh.status !== 0) throw new Error("the quickstart's commands failed");
  const app = fs.readFileSync(cwdFile, "utf8").trim();
  const generated = fs.readdirSync(path.join(app, "src/rr")).sort();
  ok(generated.includes("experimental.create.ts"), `rr-robdef ts --url wrote ${generated.join(", ")}`);
  const tscVersion = execFileSync("npx", ["tsc", "--version"], { cwd: app, env, encoding: "utf8" }).trim();
  console.log(`compiled with ${tscVersion}`);

  // the program: connected, the distance, packets
  const [cmd, ...cmdArgs] = local(runs[0].text).trim().split(/\s+/);
  const program = spawn(cmd === "node" ? process.execPath : cmd, cmdArgs, { cwd: app, stdio: ["ignore", "pipe", "inherit"] });
  children.add(program);
  const exited = new Promise((r) => program.once("exit", (code, signal) => r({ code, signal })));
  const out = lines(program);
  await out.waitFor(/^connected \(1\)$/);
  const d = await out.waitFor(/^distance: -?\d+ mm$/);
  const p1 = await out.waitFor(/^packet \d+: \d+ bytes$/, d);
  ok(true, `the program: "connected (1)", "${out.all[d]}", "${out.all[p1]}"`);

  // the gateway restarts: the program notices a going-away, comes back and streams again
  const status = await stopGateway(gateway);
  ok(status === 0, `rr-gateway exits 0 on SIGTERM (${status})`);
  const lost = await out.waitFor(/^lost: /);
  ok(/1001/.test(out.all[lost]), `the program saw the gateway go away: "${out.all[lost]}"`);
  gateway = await startGateway(port);
  const c2 = await out.waitFor(/^connected \(2\)$/, lost);
  const p2 = await out.waitFor(/^packet \d+: \d+ bytes$/, c2);
  ok(true, `after the restart: "connected (2)", "${out.all[p2]}" (onConnect asked for packets again)`);

  // Ctrl-C
  program.kill("SIGINT");
  await out.waitFor(/^closed$/, p2);
  const end = await Promise.race([exited, new Promise((r) => setTimeout(() => r({ code: "hung" }), HANG_BOUND_MS))]);
  ok(end.code === 0, `Ctrl-C: "closed", exit ${end.code ?? end.signal}`);

  // what tsc catches in the app as set up: names and values checked against the device's types
  const wrong = path.join(app, "src/wrong.ts");
  fs.writeFileSync(wrong, [
    'import { subscribe } from "robotraconteur-wasm";',
    'import type { Create } from "./rr/experimental.create.js";',
    'const sub = subscribe<Create>("rr+ws://127.0.0.1:8080/?service=create");',
    'sub.subscribeWire("packetz");                                   // line 4',
    'sub.subscribeEvent("Bumpp", () => {});                          // line 5',
    'const id: string = sub.subscribeWire("packets").inValue?.ID;   // line 6',
    'sub.subscribeWire("packets", "child");                          // line 7',
    'void id;',
    "",
  ].join("\n"));
  const r = spawnSync("npx", ["tsc", "--noEmit"], { cwd: app, env, encoding: "utf8" });
  const reported = [4, 5, 6, 7].filter((n) => new RegExp(`src/wrong\\.ts\\(${n},\\d+\\): error TS`).test(r.stdout));
  ok(r.status !== 0 && reported.length === 4, `tsc rejects a misspelled wire, event, a number as a string, a wrong objref path (lines ${reported.join(", ") || "none"})${reported.length === 4 ? "" : `\n${r.stdout}`}`);
} catch (e) {
  ok(false, `${e.stack ?? e.message}\n${e.stdout ?? ""}${e.stderr ?? ""}`);
} finally {
  if (gateway) await stopGateway(gateway);
  fs.rmSync(tmp, { recursive: true, force: true });
}
console.log(failures ? `${failures} failure(s)` : "all passed");
process.exit(failures ? 1 : 0);
