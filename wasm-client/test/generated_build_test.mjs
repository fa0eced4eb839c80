// The `.ts` modules `rr-robdef ts` writes survive the ordinary builds of an app: tsc with rootDir and
// outDir (the generated enums and constants are emitted beside the program, not left behind as a .js
// that tsc does not copy), esbuild and Vite each bundle a program that imports them, and each output runs
// under node and prints the constants' values. The program also type-checks against the package's
// index.d.ts (a typed subscription and connect), so the generated modules are checked with
// noUnusedLocals, isolatedModules and verbatimModuleSyntax too.
// Usage: node generated_build_test.mjs --rr-robdef PATH. Exit 77 (skipped) when dist/, typescript,
// esbuild or vite is missing (npm ci in wasm-client/).
import { execFileSync } from "node:child_process";
import fs from "node:fs";
import { createRequire } from "node:module";
import os from "node:os";
import path from "node:path";
import { fileURLToPath, pathToFileURL } from "node:url";

const here = path.dirname(fileURLToPath(import.meta.url));
const pkgRoot = path.resolve(here, "..");
const dist = path.join(pkgRoot, "dist");
const arg = (name) => { const i = process.argv.indexOf(name); return i > 0 ? process.argv[i + 1] : undefined; };
const robdefBin = arg("--rr-robdef");

function skip(why) { console.log(`SKIP: ${why}`); process.exit(77); }
if (!robdefBin) { console.error("usage: generated_build_test.mjs --rr-robdef PATH"); process.exit(2); }
if (!fs.existsSync(path.join(dist, "robotraconteur_wasm.wasm"))) skip("wasm-client/dist not built (wasm-client/build.sh)");
// The build tools: wasm-client's devDependencies (package.json), found as node finds them from there.
const requireTool = createRequire(path.join(pkgRoot, "package.json"));
const tool = (name, file) => { try { return path.join(path.dirname(requireTool.resolve(`${name}/package.json`)), file); } catch { return null; } };
const tsc = tool("typescript", "bin/tsc");
const esbuildMain = tool("esbuild", "lib/main.js");
const vitePkg = tool("vite", "package.json");
const missing = [!tsc && "typescript", !esbuildMain && "esbuild", !vitePkg && "vite"].filter(Boolean);
if (missing.length) skip(`${missing.join(", ")} missing (npm ci in wasm-client/)`);

let failures = 0;
const ok = (cond, what) => { console.log(`${cond ? "ok" : "FAIL"}: ${what}`); if (!cond) failures++; };
const run = (cmd, args, opts = {}) => execFileSync(cmd, args, { encoding: "utf8", stdio: ["ignore", "pipe", "pipe"], ...opts });

// What every build's output must print: the generated constants and enum values, read at run time.
const expected = JSON.stringify({ drive: 32767, spin: -1, kinds: ["number", "number"] });
const program = `import { subscribe, RRError } from "robotraconteur-wasm";
import { Create as CreateConstants, type Create, type SensorPacket } from "./rr/experimental.create.js";
import type { WebcamHost, WebcamImage } from "./rr/experimental.createwebcam.js";

// Typed only (never run here): a subscription checked against the generated interfaces.
export function typedOnly(url: string): void {
  const sub = subscribe<Create>(url);
  sub.onConnect((_client, create) => void create.StartStreaming());
  sub.subscribeWire("packets").onValueChanged((p: SensorPacket | null) => console.log(p?.ID));
  const frames = subscribe<WebcamHost>(url).subscribePipe("FrameStream", "Webcams[0]");
  frames.onPacketReceived((f: WebcamImage | null) => console.log(f?.width));
  void RRError;
}

const constants = { drive: CreateConstants.DRIVE_STRAIGHT, spin: CreateConstants.SPIN_CLOCKWISE };
console.log(JSON.stringify({ ...constants, kinds: Object.values(constants).map((v) => typeof v) }));
`;

const app = fs.mkdtempSync(path.join(os.tmpdir(), "rr-generated-build-"));
try {
  fs.writeFileSync(path.join(app, "package.json"), JSON.stringify({ name: "generated-build", private: true, type: "module" }));
  fs.mkdirSync(path.join(app, "node_modules"));
  fs.symlinkSync(dist, path.join(app, "node_modules/robotraconteur-wasm"), "dir");
  fs.symlinkSync(path.join(pkgRoot, "node_modules/ws"), path.join(app, "node_modules/ws"), "dir");
  fs.mkdirSync(path.join(app, "src"));
  fs.writeFileSync(path.join(app, "src/main.ts"), program);
  run(robdefBin, ["ts", "-o", path.join(app, "src/rr"), "--builtin", "experimental.create", "--builtin", "experimental.createwebcam"]);
  const generated = fs.readdirSync(path.join(app, "src/rr")).sort();
  ok(generated.join() === "experimental.create.ts,experimental.createwebcam.ts", `rr-robdef ts writes one .ts module per definition: ${generated.join(", ")}`);

  // 1. tsc with rootDir/outDir and the strict options a project may have
  fs.writeFileSync(path.join(app, "tsconfig.json"), JSON.stringify({
    compilerOptions: {
      target: "ES2022", module: "NodeNext", moduleResolution: "NodeNext", strict: true, rootDir: "src", outDir: "out-tsc",
      types: [], noUnusedLocals: true, noUnusedParameters: true, isolatedModules: true, verbatimModuleSyntax: true,
      exactOptionalPropertyTypes: true, noImplicitOverride: true, skipLibCheck: false,
    },
    include: ["src"],
  }, null, 2));
  try {
    run(process.execPath, [tsc, "-p", app]);
    ok(fs.existsSync(path.join(app, "out-tsc/rr/experimental.create.js")), "tsc (rootDir src, outDir out-tsc, strict, noUnusedLocals, verbatimModuleSyntax) emits the generated modules too");
    const out = run(process.execPath, [path.join(app, "out-tsc/main.js")], { cwd: app }).trim();
    ok(out === expected, `node out-tsc/main.js: ${out}`);
  } catch (e) {
    ok(false, `tsc build:\n${e.stdout ?? ""}${e.stderr ?? ""}${e.message}`);
  }

  // 2. esbuild: one bundle (the package stays an import, as in a node app)
  try {
    const esbuild = await import(pathToFileURL(esbuildMain).href);
    await (esbuild.build ?? esbuild.default.build)({
      entryPoints: [path.join(app, "src/main.ts")], bundle: true, platform: "node", format: "esm", target: "node18",
      outfile: path.join(app, "out-esbuild/main.js"), external: ["robotraconteur-wasm", "ws"], logLevel: "silent",
    });
    const out = run(process.execPath, [path.join(app, "out-esbuild/main.js")], { cwd: app }).trim();
    ok(out === expected, `esbuild bundle: ${out}`);
  } catch (e) {
    ok(false, `esbuild build: ${e.stdout ?? ""}${e.stderr ?? ""}${e.message}`);
  }

  // 3. Vite (library build of the program)
  try {
    const entry = JSON.parse(fs.readFileSync(vitePkg, "utf8")).exports["."];
    const vite = await import(pathToFileURL(path.join(path.dirname(vitePkg), typeof entry === "string" ? entry : entry.import?.default ?? entry.import ?? entry.default)).href);
    await vite.build({
      root: app, configFile: false, logLevel: "silent",
      build: {
        outDir: path.join(app, "out-vite"), emptyOutDir: true, minify: false, target: "node18", ssr: path.join(app, "src/main.ts"),
        rollupOptions: { external: ["robotraconteur-wasm", "ws"], output: { format: "es", entryFileNames: "main.js" } },
      },
    });
    const out = run(process.execPath, [path.join(app, "out-vite/main.js")], { cwd: app }).trim();
    ok(out === expected, `vite build: ${out}`);
  } catch (e) {
    ok(false, `vite build: ${e.stdout ?? ""}${e.stderr ?? ""}${e.stack ?? e.message}`);
  }
} catch (e) {
  ok(false, `${e.message}\n${e.stdout ?? ""}${e.stderr ?? ""}`);
} finally {
  fs.rmSync(app, { recursive: true, force: true });
}
console.log(failures ? `${failures} failure(s)` : "all passed");
process.exit(failures ? 1 : 0);
