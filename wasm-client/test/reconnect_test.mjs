// Reconnecting subscriptions in node (reconnect_checks.mjs) with the BUILT package (wasm-client/dist):
//   direct:  rr+ws straight to rr_interop_service --websocket, through a TCP proxy the test controls
//            (device restarted, network cut silently, connections dropped)
//   gateway: rr+ws to rr-gateway in front of the service, through the proxy (device restarted, gateway
//            restarted, network cut, 100 reconnects with the heap measured after a full GC)
//   filter:  subscribe({gateway, serviceTypes}) found through the gateway's device list, across a gateway restart
//   then: heartbeatPeriodMs >= receiveTimeoutMs is refused (how fast a silent peer is dropped, and that
//         heartbeats keep an idle connection: timeouts_test.mjs, labelled timing)
//
// Usage: node --expose-gc reconnect_test.mjs --interop-service PATH --gateway PATH [--target NAME] [--reconnects N]
// Exit: 0 passed, 1 a check failed, 2 setup failed, 77 emscripten absent (package cannot be built).
import { existsSync } from "node:fs";
import { spawnSync } from "node:child_process";
import { dirname, join } from "node:path";
import { fileURLToPath } from "node:url";
import { arg, cutProxy, freePort, gateway, interopService, sleep, stopAll } from "./reconnect_harness.mjs";
import { FAST, runReconnectChecks } from "./reconnect_checks.mjs";

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
if (typeof globalThis.gc !== "function") {
  console.error("run with node --expose-gc (the memory check needs a full GC)");
  process.exit(2);
}
const rr = await import(dist);
const heap = () => {
  globalThis.gc();
  globalThis.gc();
  return process.memoryUsage().heapUsed;
};
const reconnects = Number(arg("--reconnects", "100"));

const targets = {
  async direct() {
    const svc = await interopService(arg("--interop-service"), await freePort());
    const proxy = await cutProxy(svc.port);
    return {
      url: `rr+ws://127.0.0.1:${proxy.port}/?service=interop`,
      control: { restartDevice: () => svc.restart(), cut: () => proxy.cut(), restore: () => proxy.restore() },
    };
  },
  async gateway() {
    const svc = await interopService(arg("--interop-service"), await freePort());
    const gw = await gateway(arg("--gateway"), await freePort(), svc.tcpUrl);
    await gw.start();
    const proxy = await cutProxy(gw.port);
    return {
      url: `rr+ws://127.0.0.1:${proxy.port}/?service=interop`,
      heap,
      control: { restartDevice: () => svc.restart(), restartGateway: () => gw.restart(), cut: () => proxy.cut(),
        restore: () => proxy.restore(), dropAll: () => proxy.dropAll() },
    };
  },
};

let failed = 0;
let ran = 0;
const chosen = arg("--target") ? [arg("--target")] : [...Object.keys(targets), "filter"];
for (const name of chosen) {
  if (name === "filter") continue;
  let t;
  try {
    t = await targets[name]();
  } catch (e) {
    console.error(`${name}: setup failed: ${e.message}`);
    process.exit(2);
  }
  console.log(`== ${name}: ${t.url}`);
  const r = await runReconnectChecks(rr, { url: t.url, control: t.control, heap: t.heap, reconnects, log: (l) => console.log(`  ${l}`) });
  console.log(`== ${name}: ${r.passed.length} passed, ${r.failed.length} failed`);
  failed += r.failed.length;
  ran++;
  stopAll();
}

// A filter (service type) resolved through the gateway's device list; kept across a gateway restart.
if (chosen.includes("filter")) {
  const svc = await interopService(arg("--interop-service"), await freePort());
  const gw = await gateway(arg("--gateway"), await freePort(), svc.tcpUrl);
  await gw.start();
  const results = [];
  const ok = (cond, what) => {
    results.push(cond);
    console.log(`  ${cond ? "ok  " : "FAIL"} ${what}`);
  };
  console.log(`== filter: {gateway: ${gw.http}, serviceTypes: [experimental.interop_test.Root]}`);
  const none = rr.subscribe({ gateway: gw.http, serviceTypes: ["experimental.nosuch.Thing"] }, { ...FAST, discoveryIntervalMs: 200 });
  const sub = rr.subscribe({ gateway: gw.http, serviceTypes: ["experimental.interop_test.Root"] }, { ...FAST, discoveryIntervalMs: 200 });
  const wire = sub.subscribeWire("w_state");
  try {
    const c = await sub.getDefaultClientWait(30000);
    ok(c.$type === "experimental.interop_test.Root" && sub.clients.length === 1 && sub.clients[0].serviceInfo.device === "interop",
      `matched the gateway's device: ${sub.clients.map((x) => `${x.id} ${x.url}`).join(", ")}`);
    ok(await wire.waitInValueValid(30000), "wire value through the filter's connection");
    await gw.restart();
    const again = await sub.getDefaultClientWait(30000);
    const v0 = wire.tryGetInValue();
    // a value the new connection brought (the service ticks), not a pause
    let fresh = false;
    const offFresh = wire.onValueChanged(() => (fresh = true));
    for (const end = Date.now() + 30000; !fresh && Date.now() < end;) await sleep(10);
    offFresh?.();
    ok(again.$type === "experimental.interop_test.Root" && sub.clients[0].connectCount === 2 && fresh && wire.tryGetInValue() !== v0,
      `after a gateway restart: connectCount ${sub.clients[0].connectCount}, wire values again (${fresh ? "a new one came" : "none in 30 s"})`);
    ok(none.clients.length === 0 && none.state === "connecting", "a filter nothing matches connects to nothing");
    // Two URLs (the service through the gateway and directly): two clients, values from both.
    const two = rr.subscribe([gw.rrUrl, svc.wsUrl], FAST);
    const w2 = two.subscribeWire("w_state");
    const from = new Set();
    w2.onValueChanged((v, ts, client) => from.add(client.id));
    for (const end = Date.now() + 30000; (from.size < 2 || w2.activeWireConnectionCount < 2) && Date.now() < end;) await sleep(20);
    ok(two.clients.length === 2 && two.getConnectedClients().size === 2 && w2.activeWireConnectionCount === 2 && from.size === 2,
      `two URLs: ${two.getConnectedClients().size} connected, ${w2.activeWireConnectionCount} wire connections, values from ${from.size}`);
    await two.close();
    let bad = null;
    try {
      rr.subscribe({ serviceTypes: ["x"] });
    } catch (e) {
      bad = e;
    }
    ok(bad?.errorName === "RobotRaconteur.InvalidArgument", `a filter without gateway: ${bad?.message}`);
  } catch (e) {
    ok(false, e.message);
  }
  await sub.close();
  await none.close();
  failed += results.filter((x) => !x).length;
  ran++;
  stopAll();
}
// Heartbeats are for a peer that answers them: a period that is not shorter than the receive timeout
// would drop every idle connection, so connect() refuses it.
if (!arg("--target")) {
  let bad = null;
  try {
    await rr.connect("rr+ws://127.0.0.1:9/?service=interop", { heartbeatPeriodMs: 2000, receiveTimeoutMs: 1000 });
  } catch (e) {
    bad = e;
  }
  const badOk = bad?.errorName === "RobotRaconteur.InvalidArgument";
  console.log(`  ${badOk ? "ok  " : "FAIL"} heartbeatPeriodMs >= receiveTimeoutMs refused: ${bad?.message}`);
  if (!badOk) failed++;
}
console.log(failed ? `FAILED: ${failed} checks` : `all checks passed (${ran} targets)`);
process.exit(failed ? 1 : 0);
