// What the package's Chromium tests need before they start: Debian's Chromium, playwright-core (from
// web/node_modules) and a built wasm-client/dist. Exits 77 (ctest: skipped) with the reason when one is
// absent and cannot be made here, 2 when dist only needs building.
import { existsSync } from "node:fs";
import { spawnSync } from "node:child_process";
import { createRequire } from "node:module";
import { dirname, join } from "node:path";
import { fileURLToPath } from "node:url";

export const CHROMIUM = "/usr/bin/chromium";

/** Checks the prerequisites (or exits as above) and returns playwright-core's `chromium` launcher. */
export function chromiumOrSkip() {
  const pkgRoot = join(dirname(fileURLToPath(import.meta.url)), "..");
  const playwrightPath = join(pkgRoot, "..", "web", "node_modules", "playwright-core");
  for (const [what, path] of [["Chromium", CHROMIUM], ["playwright-core (web/node_modules)", playwrightPath]]) {
    if (!existsSync(path)) {
      console.log(`SKIP: ${what} missing: ${path} (run scripts/setup.sh)`);
      process.exit(77);
    }
  }
  if (!existsSync(join(pkgRoot, "dist", "robotraconteur.mjs"))) {
    if (spawnSync("sh", ["-c", "command -v emcmake"]).status !== 0) {
      console.log("SKIP: emscripten is not installed, so wasm-client/dist cannot be built (run scripts/setup.sh)");
      process.exit(77);
    }
    console.error("wasm-client/dist missing: run wasm-client/build.sh (scripts/test.sh does)");
    process.exit(2);
  }
  return createRequire(import.meta.url)(playwrightPath).chromium;
}
