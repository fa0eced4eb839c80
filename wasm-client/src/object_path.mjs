// Object paths (`arms[left].tool`, `child_by_int[7]`): parsed by the C++ core's one parser
// (base/names/object_path.hpp, compiled into the WebAssembly module), so JS reads a path exactly as the
// gateway, the service side and recording do, and fails with the same messages.
import { toRRError } from "./errors.mjs";

/**
 * Parses `path` (segments `name` or `name[index]` joined by '.'; an index is any text but ']', or in
 * RR's service-path encoding, `%2d1` for "-1"). Resolves with its segments, [{name, index?}] (`index`
 * decoded, absent without brackets); rejects with RRError InvalidArgument and the core's message
 * (`object path "a..b": expected a member name at offset 2`).
 */
export async function parseObjectPath(path) {
  // Imported on first use: subscription.mjs (and the dashboard's tests that run it from source, without
  // a WebAssembly build) load this file without needing the module until a path is parsed.
  const { loadModule } = await import("./wasm_module.mjs");
  const M = await loadModule();
  const r = M.parseObjectPath(String(path));
  if (!r.ok) throw toRRError(r.error);
  return r.value;
}
