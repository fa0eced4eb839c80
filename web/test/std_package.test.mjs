// The standard types as the client package ships them (robotraconteur-wasm/std, wasm-client/build.sh):
// every export of src/std/index.js declared in its index.d.ts and nothing declared that is not there,
// and nothing imported from outside std/ (the package build copies the folder, not a list of files).
import { test } from "node:test";
import assert from "node:assert/strict";
import fs from "node:fs";
import path from "node:path";
import { fileURLToPath } from "node:url";
import * as std from "../src/std/index.js";

const dir = path.join(path.dirname(fileURLToPath(import.meta.url)), "../src/std");

test("index.d.ts declares exactly the runtime exports of index.js", () => {
  const dts = fs.readFileSync(path.join(dir, "index.d.ts"), "utf8");
  const declared = new Set([...dts.matchAll(/^export (?:function|class|const) (\w+)/gm)].map((m) => m[1]));
  const runtime = new Set(Object.keys(std));
  assert.deepEqual([...runtime].filter((n) => !declared.has(n)).sort(), [], "exported but not declared");
  assert.deepEqual([...declared].filter((n) => !runtime.has(n)).sort(), [], "declared but not exported");
});

test("the std modules import nothing from outside std/ (the package copies the folder as it is)", () => {
  const outside = new Set();
  for (const f of fs.readdirSync(dir).filter((f) => f.endsWith(".js"))) {
    for (const m of fs.readFileSync(path.join(dir, f), "utf8").matchAll(/(?:from|import\() ?"([^"]+)"/g)) {
      if (!m[1].startsWith("./")) outside.add(`${f}: ${m[1]}`);
    }
  }
  assert.deepEqual([...outside].sort(), []);
});
