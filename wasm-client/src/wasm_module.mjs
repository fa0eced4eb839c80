// The WebAssembly module (robotraconteur_wasm.mjs + .wasm: the C++ client core and core's object path
// parser), loaded once for every connection and every parse.
import createRRModule from "./robotraconteur_wasm.mjs";

const isNode = typeof process !== "undefined" && !!process.versions?.node && typeof window === "undefined";

let modulePromise = null;
/** Loads and instantiates the WebAssembly module once. */
export function loadModule() {
  if (!modulePromise) {
    modulePromise = (async () => {
      const opts = {};
      if (isNode) {
        // The module is built for the web; in node it gets the bytes instead of fetching a file: URL.
        const fs = await import("node:fs/promises");
        opts.wasmBinary = await fs.readFile(new URL("./robotraconteur_wasm.wasm", import.meta.url));
      }
      return createRRModule(opts);
    })();
  }
  return modulePromise;
}
