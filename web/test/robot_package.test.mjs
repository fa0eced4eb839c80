// The robot modules as the client package ships them (robotraconteur-wasm/robot/*.js: web/src/robot
// copied whole into dist/dashboard/robot by wasm-client/build.sh): kinematics.js and view3d.js have
// declarations naming exactly their exports, and no module of the folder imports anything the package
// does not hold (only each other, ../std/*, and three, the package's optional peer dependency).
import { test } from "node:test";
import assert from "node:assert/strict";
import fs from "node:fs";
import path from "node:path";
import { fileURLToPath } from "node:url";

const dir = path.join(path.dirname(fileURLToPath(import.meta.url)), "../src/robot");
const exportsOf = (text, re) => new Set([...text.matchAll(re)].map((m) => m[1]));

for (const name of ["kinematics", "view3d"]) {
  test(`robot/${name}.d.ts declares exactly the exports of robot/${name}.js`, () => {
    const js = fs.readFileSync(path.join(dir, `${name}.js`), "utf8");
    const dts = fs.readFileSync(path.join(dir, `${name}.d.ts`), "utf8");
    const runtime = exportsOf(js, /^export (?:async )?(?:function|class|const|let) (\w+)/gm);
    const declared = exportsOf(dts, /^export (?:function|class|const) (\w+)/gm);
    assert.ok(runtime.size > 0);
    assert.deepEqual([...runtime].filter((n) => !declared.has(n)).sort(), [], "exported but not declared");
    assert.deepEqual([...declared].filter((n) => !runtime.has(n)).sort(), [], "declared but not exported");
  });
}

test("web/src/robot imports only itself, ../std/ and three (what the package holds)", () => {
  const std = new Set(fs.readdirSync(path.join(dir, "../std")));
  const bad = [];
  for (const f of fs.readdirSync(dir).filter((f) => f.endsWith(".js"))) {
    const text = fs.readFileSync(path.join(dir, f), "utf8");
    for (const [, spec] of text.matchAll(/(?:from|import\()\s*"([^"]+)"/g)) {
      const fine = /^three(\/addons\/.+)?$/.test(spec)
        || (/^\.\/[\w.-]+\.js$/.test(spec) && fs.existsSync(path.join(dir, spec)))
        || (/^\.\.\/std\/[\w.-]+\.js$/.test(spec) && std.has(path.basename(spec)));
      if (!fine) bad.push(`${f}: ${spec}`);
    }
  }
  assert.deepEqual(bad, [], "page modules (dom.js, views/, panels/) stay outside web/src/robot, or the package must copy them too");
});
