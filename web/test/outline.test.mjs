// The robdef outline (src/std/robdef_outline.js) over the seed paper's definitions and the standard ones
// in ../shared (skipped when absent): every field type is a primitive or resolves to a declared type.
import { test } from "node:test";
import assert from "node:assert/strict";
import fs from "node:fs";
import path from "node:path";
import { fileURLToPath } from "node:url";
import { RobdefOutline, outlineDefinition } from "../src/std/robdef_outline.js";
import { parseType, NUMERIC_ARRAYS } from "../src/std/rr_types.js";

const shared = process.env.RR_SHARED_DIR || path.resolve(path.dirname(fileURLToPath(import.meta.url)), "../../../shared");
const PRIMITIVES = new Set([...Object.keys(NUMERIC_ARRAYS), "bool", "string", "varvalue", "varobject", "cdouble", "csingle"]);

function robdefs(dir) {
  if (!fs.existsSync(dir)) return null;
  const out = {};
  for (const entry of fs.readdirSync(dir, { recursive: true })) {
    if (String(entry).endsWith(".robdef")) {
      const text = fs.readFileSync(path.join(dir, entry), "utf8");
      out[outlineDefinition(text).name] = text;
    }
  }
  return out;
}

test("the seed Create definition: struct fields, object members and line numbers", (t) => {
  const defs = robdefs(path.join(shared, "seed-examples"));
  if (!defs) return t.skip("shared/seed-examples missing");
  const o = new RobdefOutline(defs);
  const packet = o.typeOf("SensorPacket", "experimental.create");
  assert.equal(packet.qualified, "experimental.create.SensorPacket");
  assert.deepEqual(packet.fields.map((f) => `${f.type} ${f.name}`), ["uint8 ID", "uint8[] Data"]);
  const create = o.typeOf("experimental.create.Create");
  assert.equal(create.kind, "object");
  assert.ok(create.members.some((m) => m.kind === "wire" && /SensorPacket packets/.test(m.text)));
  assert.equal(o.serviceOfObject("experimental.createwebcam.Webcam"), "experimental.createwebcam");
  const lines = defs["experimental.create"].split("\n");
  assert.match(lines[packet.line - 1], /struct\s+SensorPacket/);
});

test("standard definitions: every field type resolves", (t) => {
  const defs = robdefs(path.join(shared, "robdef-standard"));
  if (!defs) return t.skip("shared/robdef-standard missing");
  const o = new RobdefOutline(defs);
  assert.ok(o.services.length >= 40, `${o.services.length} services`);
  let fields = 0;
  for (const s of o.services) {
    for (const e of s.entries) {
      for (const f of e.fields) {
        fields++;
        const base = parseType(f.type).base;
        assert.ok(PRIMITIVES.has(base) || o.typeOf(base, s.name), `${s.name}.${e.name}.${f.name}: ${f.type}`);
      }
    }
  }
  assert.ok(fields > 300, `${fields} fields`);
  const mode = o.enumOf("RobotCommandMode", "com.robotraconteur.robotics.robot");
  assert.deepEqual(mode.slice(0, 3), [{ name: "invalid_state", value: -1 }, { name: "halt", value: 0 }, { name: "jog", value: 1 }]);
});
