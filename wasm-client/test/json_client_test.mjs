// The JSON WebSocket client (src/json_client.mjs, "robotraconteur-wasm/json") in node against a real
// rr-gateway in front of rr_interop_service, through a TCP proxy the test controls: requests, wire /
// event / pipe subscriptions, and their resumption after a gateway restart, a device restart (the
// gateway ends pipe subscriptions then; the client subscribes again) and a silent network cut.
// Every wait is for an event, bounded only against a hang; how fast the cut is noticed and when a
// request waiting through it fails are bounds of timeouts_test.mjs (labelled timing).
//
// Usage: node json_client_test.mjs --interop-service PATH --gateway PATH
// Exit: 0 passed, 1 a check failed, 2 setup failed.
import { dirname, join } from "node:path";
import { fileURLToPath } from "node:url";
import { arg, checks, cutProxy, freePort, gateway, interopService, sleep, stopAll, until } from "./reconnect_harness.mjs";

const here = dirname(fileURLToPath(import.meta.url));
// The source module: it needs no build (no wasm), and dist/json_client.mjs is a copy of it.
const { connectJson, decodeBinaryPush } = await import(join(here, "..", "src", "json_client.mjs"));

// Quick reconnects; the receive timeout well above a stall of node or the gateway under CI load (a
// spurious one is one reconnect too many), the request timeout a bound on a hang.
const FAST = { backoff: { initialMs: 50, maxMs: 400 }, heartbeatPeriodMs: 500, receiveTimeoutMs: 6000, timeoutMs: 30000 };
const { ok, failed } = checks();

let svc;
let gw;
let proxy;
try {
  svc = await interopService(arg("--interop-service"), await freePort());
  gw = await gateway(arg("--gateway"), await freePort(), svc.tcpUrl);
  await gw.start();
  proxy = await cutProxy(gw.port);
} catch (e) {
  console.error(`setup failed: ${e.message}`);
  process.exit(2);
}

const client = connectJson(`http://127.0.0.1:${proxy.port}`, FAST);
const seen = { connects: 0, disconnects: 0, wire: 0, wireKeys: new Set(), wireDup: 0, events: [], packets: [], closedPushes: 0 };
client.onConnect(() => seen.connects++);
client.onDisconnect(() => seen.disconnects++);
const dev = client.device("interop");

/** Wire, event and pipe subscriptions deliver (again), each push once. */
async function works(what) {
  await until(() => client.state === "connected", `${what}: connected`);
  const w0 = seen.wire;
  await until(() => seen.wire >= w0 + 2, `${what}: wire values`);
  await gw.deviceConnected();
  seen.events.length = 0;
  // subscribed on this socket: the gateway's subscription number, cleared when a socket or the pipe ends
  await until(() => pipeSub.socketId !== null, `${what}: pipe subscribed`);
  await dev.call("fire_events", [3]);
  await until(() => seen.events.length >= 3, `${what}: 3 events`);
  seen.packets.length = 0;
  await dev.call("send_stream", [2]);
  await until(() => seen.packets.length >= 2, `${what}: 2 packets`);
  // A fence instead of a pause: one more event and packet, pushed on the same socket after those above,
  // come after any second copy of them; the lists are compared once the fence arrived.
  await dev.call("fire_events", [1]);
  await until(() => seen.events.length >= 4, `${what}: the fence event`);
  await dev.call("send_stream", [1]);
  await until(() => seen.packets.length >= 3, `${what}: the fence packet`);
  ok(JSON.stringify(seen.events.slice(0, 4)) === "[0,1,2,0]" && JSON.stringify(seen.packets.slice(0, 3)) === "[0,1,0]" && seen.wireDup === 0,
    `${what}: events ${JSON.stringify(seen.events)}, packets ${JSON.stringify(seen.packets)} (each once, then the fence), wire values twice: ${seen.wireDup}`);
}

let pipeSub;
try {
  console.log(`== JSON client: ${client.url}`);
  ok(await dev.call("add", [2, 3]) === 5, "call add(2, 3) before the socket was open (waits for it)");
  const devices = await client.devices();
  ok(devices[0]?.name === "interop", "devices()");
  await dev.subscribe("w_state", (v, push) => {
    seen.wire++;
    const key = `${v.id}/${v.label}/${push.time.seconds}.${push.time.nanoseconds}`;
    if (seen.wireKeys.has(key)) seen.wireDup++;
    seen.wireKeys.add(key);
  });
  const evSub = await dev.subscribe("ev_values", (args) => seen.events.push(args.seq));
  ok(evSub.kind === "event", `event subscription kind ${evSub.kind}`);
  pipeSub = await dev.subscribe("p_stream", (p) => seen.packets.push(p[0]));
  pipeSub.onClose(() => seen.closedPushes++);
  ok(pipeSub.kind === "pipe", `pipe subscription kind ${pipeSub.kind}`);
  await works("first socket");

  const c0 = client.connectCount;
  await gw.restart();
  await works("after a gateway restart");
  ok(client.connectCount === c0 + 1 && seen.disconnects === 1, `one reconnect (connectCount ${client.connectCount}, onDisconnect ${seen.disconnects})`);

  const r0 = pipeSub.resubscribed;
  await svc.restart();
  await until(() => seen.closedPushes >= 1, "the pipe's closed push");
  await works("after a device restart");
  ok(pipeSub.resubscribed > r0, `pipe subscribed again after the gateway closed it (${pipeSub.resubscribed - r0} times)`);

  const d0 = seen.disconnects;
  const c1 = client.connectCount;
  const t0 = performance.now();
  proxy.cut();
  await until(() => seen.disconnects > d0, "onDisconnect after the cut", FAST.receiveTimeoutMs + 30000);
  const noticed = performance.now() - t0;
  ok(client.state !== "connected", `silent cut noticed after ${Math.round(noticed)} ms (receiveTimeoutMs ${FAST.receiveTimeoutMs}): state ${client.state}`);
  // A request made while there is no socket waits for one: answered once the network is back.
  const during = dev.get("p_double").then((v) => ({ v }), (e) => ({ e }));
  proxy.restore();
  const answer = await during;
  ok(typeof answer.v === "number" && client.connectCount === c1 + 1,
    `a request made during the cut is answered after it: ${answer.e ? `${answer.e.errorName}: ${answer.e.message}` : answer.v}; connectCount ${c1} -> ${client.connectCount}`);
  await works("after the cut");

  // maxRateHz / queueLength (docs/json-api.md "Rate and queue length"): values arrive thinned, in
  // order, the last one always; compared once that last value arrived (an event, not a pause). Paced:
  // each value is sent once the unlimited subscriber got the one before, so the socket is never behind
  // and only the rate (not backpressure's coalescing) thins the limited subscriber.
  const limitedSeen = [];
  const senderSeen = [];
  await dev.subscribe("w_both", (v) => limitedSeen.push(v[0]), { maxRateHz: 1 });
  const sender = await dev.subscribe("w_both", (v) => senderSeen.push(v[0]));
  const N = 30;  // at 1 value/s these would need 30 s to all go
  for (let i = 0; i < N; ++i) {
    await sender.setOutValue([i]);
    await until(() => senderSeen.at(-1) === i, `value ${i} at the unlimited subscriber`);
  }
  await until(() => limitedSeen.at(-1) === N - 1, "the last value through maxRateHz 1");
  const increasing = limitedSeen.every((v, i) => i === 0 || v > limitedSeen[i - 1]);
  ok(limitedSeen.length < N / 2 && increasing,
    `wire at maxRateHz 1: ${limitedSeen.length} of ${N} values (the unlimited subscriber got them all), in order, the last one: ${JSON.stringify(limitedSeen)}`);
  const pipeSeen = [];
  let pipeDropped = 0;
  const limitedPipe = await dev.subscribe("p_stream", (p, push) => {
    pipeSeen.push(p[0]);
    pipeDropped += push.dropped ?? 0;
  }, { maxRateHz: 2, queueLength: 2 });
  await dev.call("send_stream", [30]);
  await until(() => pipeSeen.at(-1) === 29, "the last packet through maxRateHz 2, queueLength 2");
  ok(pipeSeen.length < 30 && pipeSeen.length + pipeDropped === 30 && pipeSeen.at(-2) === 28,
    `pipe at maxRateHz 2, queueLength 2: ${JSON.stringify(pipeSeen)}, ${pipeDropped} dropped (counted in push.dropped)`);
  await limitedPipe.close();
  const refusal = async (member, options) => {
    try {
      await dev.subscribe(member, () => {}, options);
      return "accepted";
    } catch (e) {
      return e.errorName;
    }
  };
  const refusals = [await refusal("w_both", { maxRateHz: 0 }), await refusal("w_both", { maxRateHz: 5000 }),
    await refusal("p_stream", { queueLength: 3 }), await refusal("ev_values", { maxRateHz: 1 })];
  ok(refusals.every((r) => r === "RobotRaconteur.InvalidArgument"), `bad maxRateHz / queueLength refused: ${refusals.join(", ")}`);

  const json = new TextEncoder().encode('{"v":{"$binary":0,"type":"uint8","length":3,"offset":0}}');
  const buf = new Uint8Array(8 + json.length + 16);
  buf.set([0x52, 0x52, 0x4a, 0x42]);
  new DataView(buf.buffer).setUint32(4, json.length, true);
  buf.set(json, 8);
  const base = (8 + json.length + 7) & ~7;
  buf.set([7, 8, 9], base);
  const decoded = decodeBinaryPush(buf.buffer);
  ok(decoded.v instanceof Uint8Array && decoded.v.join() === "7,8,9", "decodeBinaryPush");
  let bad = null;
  try {
    decodeBinaryPush(new ArrayBuffer(4));
  } catch (e) {
    bad = e;
  }
  ok(bad?.errorName === "RobotRaconteur.ProtocolError", "a malformed binary push is a ProtocolError");

  client.close();
  const w0 = seen.wire;
  await sleep(500);
  ok(client.state === "closed" && seen.wire === w0, "close(): no more pushes, no reconnect");
} catch (e) {
  ok(false, e.message);
}
stopAll();
proxy?.close();
console.log(failed() ? `FAILED: ${failed()} checks` : "all checks passed");
process.exit(failed() ? 1 : 0);
