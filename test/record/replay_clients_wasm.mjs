// The wasm client's side of replay_clients_test.py: connects the BUILT package (wasm-client/dist) in
// node to a replayed device of rr-gateway over rr+ws, connects the w_state wire and the p_stream pipe
// and listens to ev_values, prints {"ready": true}, then answers each line on stdin:
//   "report"  one JSON line {"wire": [ids received, in order], "in_value": id of the wire's InValue,
//             "pipe": [[i, x], …], "events": [[seq, text, id], …], "property": p_int32's value,
//             "function_error": {"errorName", "message"} of add(1, 2) (null if it did not fail)}
//   "quit"    closes the client and exits 0.
// Usage: node replay_clients_wasm.mjs URL. Exit 2 when the connect fails, 77 without wasm-client/dist.
import { existsSync } from "node:fs";
import { createInterface } from "node:readline";
import { dirname, join } from "node:path";
import { fileURLToPath, pathToFileURL } from "node:url";

const here = dirname(fileURLToPath(import.meta.url));
const dist = join(here, "..", "..", "wasm-client", "dist", "robotraconteur.mjs");
if (!existsSync(dist)) {
  console.log(`SKIP: ${dist} missing (run wasm-client/build.sh)`);
  process.exit(77);
}
const rr = await import(pathToFileURL(dist).href);
const url = process.argv[2];

let c;
try {
  c = await rr.connect(url, { timeoutMs: 20000 });
} catch (e) {
  console.error(`wasm client: connect ${url}: ${e.errorName ?? ""} ${e.message}`);
  process.exit(2);
}
const wire = [];
const pipe = [];
const events = [];
const w = await c.w_state.connect();
w.onChange((value) => wire.push(value.id));
const ep = await c.p_stream.connect();
ep.onPacket((packet) => pipe.push(Array.from(packet, Number)));
c.ev_values.on((seq, text, data) => events.push([seq, text, data.id]));
console.log(JSON.stringify({ ready: true }));

async function report() {
  let functionError = null;
  try {
    await c.add(1, 2);
  } catch (e) {
    functionError = { errorName: e.errorName, message: e.message };
  }
  let property = null;
  try {
    property = await c.p_int32.get();
  } catch (e) {
    property = { errorName: e.errorName, message: e.message };
  }
  return {
    wire: [...wire],
    in_value: w.inValueValid ? w.inValue.id : null,
    pipe: [...pipe],
    events: [...events],
    property,
    function_error: functionError,
  };
}

for await (const line of createInterface({ input: process.stdin })) {
  if (line.trim() === "report") console.log(JSON.stringify(await report()));
  else if (line.trim() === "quit") break;
}
await c.$client.close().catch(() => {});
process.exit(0);
