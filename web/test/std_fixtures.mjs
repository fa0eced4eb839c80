// Shared by the std_*.test.mjs files: the standard service definitions, read at test time from
// $RR_SHARED_DIR/robdef-standard (default ../../../shared from here), never copied into the project.
import fs from "node:fs";
import path from "node:path";
import { fileURLToPath } from "node:url";
import { outlineDefinition } from "../src/std/robdef_outline.js";

export const shared = process.env.RR_SHARED_DIR || path.resolve(path.dirname(fileURLToPath(import.meta.url)), "../../../shared");
export const standardDir = path.join(shared, "robdef-standard");

/** { service name: robdef text } of the verified standard set (group1), or null when absent. */
export function standardDefinitions() {
  const dir = path.join(standardDir, "group1");
  if (!fs.existsSync(dir)) return null;
  const out = {};
  for (const entry of fs.readdirSync(dir)) {
    if (!entry.endsWith(".robdef")) continue;
    const text = fs.readFileSync(path.join(dir, entry), "utf8");
    out[outlineDefinition(text).name] = text;
  }
  return out;
}

export const SKIP_REASON = `standard definitions missing: ${standardDir} (set RR_SHARED_DIR)`;
