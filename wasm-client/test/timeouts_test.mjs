// Timing checks of the clients' own timers in node (labelled `timing` in ctest: each bound is the check):
//   wasm:  the BUILT package (wasm-client/dist) straight to rr_interop_service --websocket through a TCP
//          proxy the test controls: timeout_checks.mjs (heartbeats, receive timeout, connect timeout,
//          rr.subscribe() across a silent cut)
//   json:  the JSON client (src/json_client.mjs) to rr-gateway in front of the service, through a proxy:
//          an idle socket kept by heartbeats, a silent cut noticed within receiveTimeoutMs + 500 ms, a
//          request during the cut failing after timeoutMs, connected again after the network is back
//
// Usage: node timeouts_test.mjs --interop-service PATH --gateway PATH
// Exit: 0 passed, 1 a check failed, 2 setup failed, 77 emscripten absent (package cannot be built).
import { existsSync } from "node:fs";
import { spawnSync } from "node:child_process";
import { dirname, join } from "node:path";
import { fileURLToPath } from "node:url";
import { arg, cutProxy, freePort, gateway, interopService, sleep, stopAll } from "./reconnect_harness.mjs";
import { runTimeoutChecks } from "./timeout_checks.mjs";

const here = dirname(fileURLToPath(import.meta.url));
const dist = join(here, "..", "dist", "robotraconteur.mjs");
if (!existsSync(dist)) {
  if (spawnSync("sh", ["-c", "command -v emcmake"]).status !== 0) {
    console.log("SKIP: emscripten is not installed, so wasm-client/dist cannot be built (run scripts/setup.sh)");
    process.exit(77);
  }
  console.error(`${dist} missing: run wasm-client/build.sh`);
  process.exit(2);
}
const rr = await import(dist);
const { connectJson } = await import(join(here, "..", "src", "json_client.mjs"));

let failed = 0;
const ok = (cond, what) => {
  console.log(`  ${cond ? "ok  " : "FAIL"} ${what}`);
  if (!cond) failed++;
};
async function until(cond, what, timeoutMs = 30000) {
  const end = performance.now() + timeoutMs;
  while (!cond()) {
    if (performance.now() > end) throw new Error(`timed out waiting for ${what}`);
    await sleep(5);
  }
}

let svc, gw, proxy, jsonProxy;
try {
  svc = await interopService(arg("--interop-service"), await freePort());
  proxy = await cutProxy(svc.port);
  gw = await gateway(arg("--gateway"), await freePort(), svc.tcpUrl);
  await gw.start();
  jsonProxy = await cutProxy(gw.port);
} catch (e) {
  console.error(`setup failed: ${e.message}`);
  stopAll();
  process.exit(2);
}

const url = `rr+ws://127.0.0.1:${proxy.port}/?service=interop`;
console.log(`== wasm: ${url}`);
const r = await runTimeoutChecks(rr, { url, control: { cut: () => proxy.cut(), restore: () => proxy.restore() }, log: (l) => console.log(`  ${l}`) });
failed += r.failed.length;
if (r.passed.length + r.failed.length !== 4) ok(false, `wasm: ${r.passed.length + r.failed.length} checks ran, not 4`);

// The JSON client keeps its socket alive by asking "devices" when the gateway was quiet for heartbeatPeriodMs.
const HEARTBEAT_MS = 300, RECEIVE_MS = 1200, REQUEST_MS = 1500, SLACK_MS = 500;
console.log(`== json: http://127.0.0.1:${jsonProxy.port}`);
const client = connectJson(`http://127.0.0.1:${jsonProxy.port}`,
  { backoff: { initialMs: 50, maxMs: 400 }, heartbeatPeriodMs: HEARTBEAT_MS, receiveTimeoutMs: RECEIVE_MS, timeoutMs: REQUEST_MS });
const seen = { disconnectAt: null, connects: 0 };
client.onConnect(() => seen.connects++);
client.onDisconnect(() => (seen.disconnectAt ??= performance.now()));
try {
  await until(() => client.state === "connected", "the JSON socket open");
  await sleep(4 * RECEIVE_MS);  // idle: the duration is the check
  ok(client.state === "connected" && seen.disconnectAt === null && client.connectCount === 1,
    `idle for ${4 * RECEIVE_MS} ms with receiveTimeoutMs ${RECEIVE_MS}: state ${client.state}, connectCount ${client.connectCount}`);
  const t0 = performance.now();
  jsonProxy.cut();
  await until(() => seen.disconnectAt !== null, "onDisconnect after the cut", RECEIVE_MS + 30000);
  const noticed = seen.disconnectAt - t0;
  ok(noticed <= RECEIVE_MS + SLACK_MS, `silent cut noticed after ${Math.round(noticed)} ms (receiveTimeoutMs ${RECEIVE_MS})`);
  const t1 = performance.now();
  const late = await client.device("interop").get("p_double").then(() => null, (e) => e);
  const waited = performance.now() - t1;
  ok(late?.errorName === "RobotRaconteur.ConnectionError" && waited >= REQUEST_MS - 20 && waited <= REQUEST_MS + SLACK_MS,
    `a request during the cut waits for the socket, then fails after timeoutMs ${REQUEST_MS}: ${late?.errorName} after ${Math.round(waited)} ms`);
  jsonProxy.restore();
  await until(() => client.state === "connected" && client.connectCount === 2, "connected again after the network is back");
  ok(true, "connected again after the network is back");
} catch (e) {
  ok(false, e.message);
}
client.close();
proxy.close();
jsonProxy.close();
stopAll();
console.log(failed ? `FAILED: ${failed} checks` : "all checks passed");
process.exit(failed ? 1 : 0);
