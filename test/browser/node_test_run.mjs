// `node --test` for ctest, with skips that count: node's runner exits 0 when tests were skipped, so a
// file whose tests all skipped (nginx, openssl or ../shared absent) would be reported "Passed". This runs
// `node --test` on the arguments (spec report on stdout, as before) and, when nothing failed but some
// test skipped, prints "SKIP: <test>: <reason>" for each and exits 77, which ctest reports as skipped
// (SKIP_RETURN_CODE 77). A failure still exits 1: fail > skip > pass.
//
// Usage: node node_test_run.mjs [node --test options] FILE|DIR...
import { spawn } from "node:child_process";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";

const dir = fs.mkdtempSync(path.join(os.tmpdir(), "rr-node-test-"));
const tap = path.join(dir, "report.tap");
const child = spawn(process.execPath, ["--test", "--test-reporter=spec", "--test-reporter-destination=stdout",
  "--test-reporter=tap", `--test-reporter-destination=${tap}`, ...process.argv.slice(2)], { stdio: "inherit" });
// ctest ends a test past its TIMEOUT with SIGTERM (then SIGKILL): pass it on, so no test is left behind
for (const sig of ["SIGTERM", "SIGINT"]) process.on(sig, () => child.kill(sig));
const { code, signal } = await new Promise((resolve) => child.on("exit", (c, s) => resolve({ code: c, signal: s })));

let skipped = [];
try {
  skipped = fs.readFileSync(tap, "utf8").split("\n")
    .map((line) => line.match(/^\s*ok \d+ - (.*?) # SKIP\b\s*(.*)$/))
    .filter(Boolean)
    .map((m) => `${m[1]}: ${m[2] || "(no reason given)"}`);
} catch {
  // no report: the runner did not get that far; its exit status says why
}
fs.rmSync(dir, { recursive: true, force: true });

if (signal || code !== 0) process.exit(code || 1);
if (skipped.length) {
  for (const s of skipped) console.log(`SKIP: ${s}`);
  console.log(`node --test: ${skipped.length} test(s) skipped, none failed: reported as skipped (exit 77)`);
  process.exit(77);
}
process.exit(0);
