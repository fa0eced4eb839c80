// The JSON WebSocket client (src/json_client.mjs) over permessage-deflate (docs/json-api.md
// "Compression", issue 56): in node < 22 the client's WebSocket is the `ws` package, which offers the
// extension. A gateway with `websocket_compression: {enabled: true}` negotiates it, and a request, wire
// values as JSON and as a binary push (arrays large enough to be deflated) arrive whole; the gateway
// without the key (the default) declines the offer and the same client works uncompressed. That binary
// frames are never deflated is checked on the frames (their RSV1 bit, which `ws` does not show) by
// test/gateway/ws_deflate_test.py.
//
// Usage: node compression_test.mjs --interop-service PATH --gateway PATH
// Exit: 0 passed, 1 a check failed, 2 setup failed, 77 skipped (no `ws` package: run ./scripts/setup.sh).
import { dirname, join } from "node:path";
import { fileURLToPath } from "node:url";
import { arg, checks, freePort, gateway, interopService, stopAll, until } from "./reconnect_harness.mjs";

const here = dirname(fileURLToPath(import.meta.url));
const { connectJson } = await import(join(here, "..", "src", "json_client.mjs"));
let ws;
try {
  ws = await import("ws");
} catch (e) {
  console.log(`SKIP: the ws package is not installed in wasm-client/node_modules (run ./scripts/setup.sh): ${e.message}`);
  process.exit(77);
}
// The client's sockets, to read what each one negotiated.
const sockets = [];
class RecordingWebSocket extends (ws.WebSocket ?? ws.default) {
  constructor(...args) {
    super(...args);
    sockets.push(this);
  }
}

const { ok, failed } = checks();

/** A request, a wire value as JSON and as a binary push through a client of `gw`; the extensions its socket got. */
async function exchange(gw, what) {
  const client = connectJson(gw.http, { WebSocket: RecordingWebSocket, timeoutMs: 30000 });
  try {
    const dev = client.device("interop");
    ok(await dev.call("add", [2, 3]) === 5, `${what}: call add(2, 3)`);
    await until(() => client.state === "connected", `${what}: connected`);
    const socket = sockets.at(-1);
    // 2,000 doubles: far above the 64 bytes under which nothing is deflated. The device echoes the
    // wire reversed.
    const sent = Array.from({ length: 2000 }, (_, i) => i * 0.5);
    const want = sent.slice().reverse();
    let asJson = null;
    let asBinary = null;
    const jsonSub = await dev.subscribe("w_both", (v) => { if (v.length === want.length) asJson = v; });
    const binSub = await dev.subscribe("w_both", (v) => { if (v.length === want.length) asBinary = v; }, { binary: true });
    await jsonSub.setOutValue(sent);
    await until(() => asJson && asBinary, `${what}: the 2,000 doubles back as JSON and as a binary push`);
    ok(Array.isArray(asJson) && asJson.every((x, i) => x === want[i]), `${what}: the wire's value as JSON, whole`);
    ok(asBinary instanceof Float64Array && asBinary.every((x, i) => x === want[i]), `${what}: the wire's value as a binary push, whole`);
    await jsonSub.close();
    await binSub.close();
    return socket.extensions;
  } finally {
    client.close();
  }
}

let svc;
let on;
let off;
try {
  svc = await interopService(arg("--interop-service"), await freePort());
  on = await gateway(arg("--gateway"), await freePort(), svc.tcpUrl, "shared", "gateway:\n  websocket_compression:\n    enabled: true\n");
  await on.start();
  off = await gateway(arg("--gateway"), await freePort(), svc.tcpUrl);
  await off.start();
} catch (e) {
  console.error(`setup failed: ${e.message}`);
  stopAll();
  process.exit(2);
}

try {
  const negotiated = await exchange(on, "compression enabled");
  ok(/permessage-deflate/.test(negotiated), `compression enabled: the client's offer was accepted (extensions: ${JSON.stringify(negotiated)})`);
  const declined = await exchange(off, "compression off (the default)");
  ok(!/permessage-deflate/.test(declined), `compression off: the offer was declined (extensions: ${JSON.stringify(declined)})`);
} catch (e) {
  ok(false, e.message);
}
stopAll();
console.log(failed() ? `FAILED: ${failed()} checks` : "all checks passed");
process.exit(failed() ? 1 : 0);
