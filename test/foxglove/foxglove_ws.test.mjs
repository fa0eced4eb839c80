// The gateway's Foxglove WebSocket (docs/foxglove.md) against the official client library
// @foxglove/ws-protocol (FoxgloveClient over `ws`): rr-gateway with logins (an operator and a viewer
// token), the demo devices as an external rr-demo-devices process (so that they can restart), and a
// command sink on the official Python library (command_sink.py) for a client publish and a clock.
//
// Checked: serverInfo and both subprotocols; every wire, pipe and event advertised with a JSON Schema
// that compiles (ajv), and the values received from the demo devices valid against their channel's
// schema; parameters read and set (and the update to a client subscribed to it); a service called
// (and a failure); a client publish reaching the device's wire and pipe; `time` messages and receive
// times from the sink's device clock (foxglove.clock); unadvertise and re-advertise (same
// channel ids) when the devices restart; a viewer refused what needs write or call; no login, a bad
// path and malformed messages answered with a status and nothing else.
//
//   RR_GATEWAY=build/debug/server/app/rr-gateway RR_DEMO_DEVICES=build/debug/server/demo/rr-demo-devices \
//     node test/browser/node_test_run.mjs test/foxglove/foxglove_ws.test.mjs
import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";
import { createRequire } from "node:module";
import { ROOT, settings, startGateway, startProcess, waitFor } from "../browser/harness.mjs";

const s = settings();
const demoDevices = process.env.RR_DEMO_DEVICES;
const require = createRequire(path.join(ROOT, "test/foxglove/package.json"));
let FoxgloveClient, WebSocket, Ajv;
let missing = "";
try {
  ({ FoxgloveClient } = require("@foxglove/ws-protocol"));
  WebSocket = require("ws");
  Ajv = require("ajv/dist/2020");  // the schemas are JSON Schema draft 2020-12
  if (Ajv.default) Ajv = Ajv.default;
} catch (e) {
  missing = `test/foxglove/node_modules incomplete (run ./scripts/setup.sh): ${e.message}`;
}
if (!missing && (!s.gateway || !demoDevices)) missing = "RR_GATEWAY and RR_DEMO_DEVICES must name the built programs";
if (!missing && !fs.existsSync(s.python)) missing = `${s.python} missing (run ./scripts/setup.sh)`;

const OPERATOR = "fox-operator-token-0123456789";
const VIEWER = "fox-viewer-token-0123456789ab";
const work = fs.mkdtempSync(path.join(os.tmpdir(), "rr-foxglove-"));
let gateway, demo, demoPort, sink;
const clients = [];

/** A FoxgloveClient on /foxglove with everything it receives kept in arrays, and waits on them. */
async function connect({ token, protocol = "foxglove.websocket.v1", target = "/foxglove" } = {}) {
  const url = `ws://127.0.0.1:${gateway.port}${target}${token ? `?token=${encodeURIComponent(token)}` : ""}`;
  const ws = new WebSocket(url, [protocol]);
  const client = new FoxgloveClient({ ws });
  const got = { serverInfo: null, channels: new Map(), services: new Map(), statuses: [], messages: [], params: [],
    responses: [], failures: [], unadvertised: [], times: [], closed: false };
  client.on("serverInfo", (m) => { got.serverInfo = m; });
  client.on("advertise", (cs) => { for (const c of cs) got.channels.set(c.id, c); });
  client.on("unadvertise", (ids) => { for (const id of ids) { got.channels.delete(id); got.unadvertised.push(id); } });
  client.on("advertiseServices", (ss) => { for (const x of ss) got.services.set(x.id, x); });
  client.on("unadvertiseServices", (ids) => { for (const id of ids) got.services.delete(id); });
  client.on("status", (m) => got.statuses.push(m));
  client.on("message", (m) => got.messages.push(m));
  client.on("parameterValues", (m) => got.params.push(m));
  client.on("serviceCallResponse", (m) => got.responses.push(m));
  client.on("serviceCallFailure", (m) => got.failures.push(m));
  client.on("time", (m) => got.times.push(m.timestamp));
  client.on("close", () => { got.closed = true; });
  client.on("error", () => {});
  clients.push(client);
  await waitFor(() => got.serverInfo || got.closed, "serverInfo or a close", 30000);
  return { client, ws, got };
}

const topicId = (got, topic) => [...got.channels.values()].find((c) => c.topic === topic)?.id;
const serviceId = (got, name) => [...got.services.values()].find((x) => x.name === name)?.id;
const text = (m) => new TextDecoder().decode(m.data);

function callService(c, name, args, callId) {
  const serviceId = [...c.got.services.values()].find((x) => x.name === name).id;
  c.client.sendServiceCallRequest({ serviceId, callId, encoding: "json", data: new TextEncoder().encode(JSON.stringify(args)) });
  return waitFor(() => c.got.responses.find((r) => r.callId === callId) || c.got.failures.find((f) => f.callId === callId),
    `the answer to call ${callId} of ${name}`, 30000);
}

before(async () => {
  if (missing) return;
  demo = await startProcess("rr-demo-devices", demoDevices, ["--listen", "127.0.0.1"], "port", 60000);
  demoPort = demo.info.port;
  sink = await startProcess("command_sink", s.python, [path.join(ROOT, "test/foxglove/command_sink.py")], "url", 60000);
  fs.writeFileSync(path.join(work, "tokens.txt"), `${OPERATOR} fox-op operator\n${VIEWER} fox-view viewer\n`, { mode: 0o600 });
  const config = path.join(work, "gateway.yaml");
  fs.writeFileSync(config, [
    "gateway:",
    "  auth:",
    `    tokens: ${path.join(work, "tokens.txt")}`,
    "    roles:",
    "      operator:",
    "        - allow: [read, write, call, lock]",
    "      viewer:",
    "        - allow: [read]",
    "demo:",
    "  enabled: false",
    "devices:",
    `  - {name: create, url: "${demo.info.create_url}"}`,
    `  - {name: webcam, url: "${demo.info.webcam_url}"}`,
    `  - {name: sink, url: "${sink.info.url}"}`,
    "foxglove:",
    "  clock: sink",
    "  objects:",
    "    webcam: [\"Webcams[0]\"]",
    "",
  ].join("\n"));
  gateway = await startGateway(s, {}, 0, ["--config", config]);
});

after(async () => {
  for (const c of clients) { try { c.close(); } catch { /* closed */ } }
  if (gateway) await gateway.child.stop();
  if (demo) await demo.child.stop();
  if (sink) await sink.child.stop();
  fs.rmSync(work, { recursive: true, force: true });
});

test("serverInfo on both subprotocols, channels advertised with JSON Schemas", { skip: missing || false }, async () => {
  const c = await connect({ token: OPERATOR });
  assert.equal(c.ws.protocol, "foxglove.websocket.v1");
  // `time`: the configuration names the sink's clock (foxglove.clock).
  assert.deepEqual(new Set(c.got.serverInfo.capabilities), new Set(["clientPublish", "parameters", "parametersSubscribe", "services", "time"]));
  assert.deepEqual(c.got.serverInfo.supportedEncodings, ["json"]);
  assert.ok(c.got.serverInfo.sessionId);
  const want = ["create/packets", "create/Bump", "webcam/Webcams[0]/FrameStream", "sink/command", "sink/command_packets"];
  await waitFor(() => want.every((t) => topicId(c.got, t) !== undefined), `advertised ${want.join(", ")}`, 30000);
  const ajv = new Ajv({ strict: false });
  for (const ch of c.got.channels.values()) {
    assert.equal(ch.encoding, "json", ch.topic);
    assert.equal(ch.schemaEncoding, "jsonschema", ch.topic);
    assert.ok(ajv.compile(JSON.parse(ch.schema)), `${ch.topic}: its schema compiles`);
  }
  assert.equal(c.got.channels.get(topicId(c.got, "create/packets")).schemaName, "experimental.create.Create.packets");
  await waitFor(() => serviceId(c.got, "create/Drive") !== undefined && serviceId(c.got, "webcam/Webcams[0]/StartStreaming") !== undefined,
    "services advertised", 30000);
  const drive = c.got.services.get(serviceId(c.got, "create/Drive"));
  assert.deepEqual(Object.keys(JSON.parse(drive.request.schema).properties), ["velocity", "radius"]);

  // The current SDK's name for the same protocol.
  const sdk = await connect({ token: OPERATOR, protocol: "foxglove.sdk.v1" });
  assert.equal(sdk.ws.protocol, "foxglove.sdk.v1");
  await waitFor(() => topicId(sdk.got, "create/packets") !== undefined, "advertise on foxglove.sdk.v1", 30000);
  assert.equal(topicId(sdk.got, "create/packets"), topicId(c.got, "create/packets"));
});

test("values of every demo device arrive and are valid against their channel's schema", { skip: missing || false }, async () => {
  const c = await connect({ token: OPERATOR });
  const topics = ["create/packets", "webcam/Webcams[0]/FrameStream"];
  await waitFor(() => topics.every((t) => topicId(c.got, t) !== undefined), "advertised", 30000);
  const subs = new Map(topics.map((t) => [c.client.subscribe(topicId(c.got, t)), t]));
  // The camera streams once asked (a service call); the create's wire has a value from the start.
  const started = await callService(c, "webcam/Webcams[0]/StartStreaming", {}, 1);
  assert.ok(!started.message, `StartStreaming: ${started.message}`);
  await waitFor(() => [...subs.keys()].every((id) => c.got.messages.some((m) => m.subscriptionId === id)),
    "a message on every subscription", 60000);
  const ajv = new Ajv({ strict: false });
  for (const [id, topic] of subs) {
    const ch = c.got.channels.get(topicId(c.got, topic));
    const validate = ajv.compile(JSON.parse(ch.schema));
    const m = c.got.messages.find((x) => x.subscriptionId === id);
    const value = JSON.parse(text(m));
    assert.ok(validate(value), `${topic}: ${JSON.stringify(validate.errors)} in ${text(m).slice(0, 300)}`);
    assert.ok(m.timestamp > 0n, `${topic}: a receive time`);
  }
  const frame = JSON.parse(text(c.got.messages.find((x) => subs.get(x.subscriptionId) === topics[1])));
  assert.ok(frame.value.width > 0 && frame.value.data.length === frame.value.height * frame.value.step, "a whole camera frame");
  await callService(c, "webcam/Webcams[0]/StopStreaming", {}, 2);
  assert.equal(c.got.statuses.filter((x) => x.level === 2).length, 0, JSON.stringify(c.got.statuses));
});

test("parameters read and set, the update to a subscribed client", { skip: missing || false }, async () => {
  const c = await connect({ token: OPERATOR });
  const watcher = await connect({ token: OPERATOR });
  watcher.client.subscribeParameterUpdates(["sink/label"]);
  await waitFor(() => watcher.got.params.some((p) => p.parameters.some((x) => x.name === "sink/label")),
    "the subscribed parameter's current value", 30000);
  c.client.getParameters(["create/DistanceTraveled", "webcam/Webcams[0]/Name", "sink/label"], "get-1");
  const got = await waitFor(() => c.got.params.find((p) => p.id === "get-1"), "parameterValues get-1", 30000);
  const byName = Object.fromEntries(got.parameters.map((p) => [p.name, p.value]));
  assert.equal(typeof byName["create/DistanceTraveled"], "number");
  assert.equal(typeof byName["webcam/Webcams[0]/Name"], "string");
  assert.equal(byName["sink/label"], "sink");

  c.client.setParameters([{ name: "sink/label", value: "foxglove" }], "set-1");
  const set = await waitFor(() => c.got.params.find((p) => p.id === "set-1"), "parameterValues set-1", 30000);
  assert.deepEqual(set.parameters, [{ name: "sink/label", value: "foxglove" }], JSON.stringify(c.got.statuses));
  await waitFor(() => watcher.got.params.some((p) => p.parameters.some((x) => x.name === "sink/label" && x.value === "foxglove")),
    "the update at the subscribed client", 30000);
  // A property the device refuses to set: a status naming the device's error, the value unchanged.
  c.client.setParameters([{ name: "webcam/Webcams[0]/Name", value: "renamed" }], "set-2");
  const refused = await waitFor(() => c.got.params.find((p) => p.id === "set-2"), "parameterValues set-2", 30000);
  assert.deepEqual(refused.parameters, []);
  assert.ok(c.got.statuses.some((x) => x.level === 2 && /webcam\/Webcams\[0\]\/Name: RobotRaconteur\.ReadOnlyMember/.test(x.message)),
    JSON.stringify(c.got.statuses));
  // All parameters: every readable property of every device.
  c.client.getParameters([], "all");
  const all = await waitFor(() => c.got.params.find((p) => p.id === "all"), "parameterValues all", 30000);
  for (const n of ["create/Bumpers", "webcam/WebcamNames", "sink/commands", "sink/label"]) assert.ok(all.parameters.some((p) => p.name === n), n);
});

test("a service called, and a failure as serviceCallFailure", { skip: missing || false }, async () => {
  const c = await connect({ token: OPERATOR });
  await waitFor(() => serviceId(c.got, "create/StartStreaming") !== undefined, "services", 30000);
  const ok = await callService(c, "create/StartStreaming", {}, 7);
  assert.equal(ok.encoding, "json");
  assert.deepEqual(JSON.parse(text(ok)), { return: null });
  const bad = await callService(c, "create/Drive", { velocity: "fast" }, 8);
  assert.equal(bad.op, "serviceCallFailure");
  assert.match(bad.message, /velocity|radius/);
  await callService(c, "create/StopStreaming", {}, 9);
});

test("a client publish reaches the device's wire", { skip: missing || false }, async () => {
  const c = await connect({ token: OPERATOR });
  await waitFor(() => topicId(c.got, "sink/command") !== undefined, "sink/command advertised", 30000);
  const channel = c.client.advertise({ topic: "sink/command", encoding: "json", schemaName: "experimental.foxglove_sink.Sink.command" });
  const send = (v) => c.client.sendMessage(channel, new TextEncoder().encode(JSON.stringify(v)));
  send({ value: [1.5, -2, 3] });
  const read = async () => {
    c.client.getParameters(["sink/last_command"], `read-${c.got.params.length}`);
    const n = c.got.params.length;
    const p = await waitFor(() => c.got.params.length > n && c.got.params[c.got.params.length - 1], "sink/last_command", 30000);
    return p.parameters[0]?.value;
  };
  await waitFor(async () => JSON.stringify(await read()) === "[1.5,-2,3]", `the published value at the device (${JSON.stringify(c.got.statuses)})`, 30000, 200);
  send([4, 5]);  // the bare value works too
  await waitFor(async () => JSON.stringify(await read()) === "[4,5]", "the bare published value at the device", 30000, 200);
  send({ value: "not numbers" });
  await waitFor(() => c.got.statuses.some((x) => x.level === 2 && /sink\/command/.test(x.message)), "a status for a bad value", 30000);
  // A topic that is no writable wire (Lichtblick advertises ROS topics of its own): accepted silently,
  // its messages refused with one status, not one per message.
  const other = c.client.advertise({ topic: "/clicked_point", encoding: "json", schemaName: "geometry_msgs/PointStamped" });
  const before = c.got.statuses.length;
  for (let i = 0; i < 3; ++i) c.client.sendMessage(other, new TextEncoder().encode("{}"));
  send([7, 8]);  // in order after those: once it arrives, their statuses are in
  await waitFor(async () => JSON.stringify(await read()) === "[7,8]", "a value after the refused ones", 30000, 200);
  const refused = c.got.statuses.slice(before).filter((x) => /clicked_point/.test(x.message));
  assert.equal(refused.length, 1, JSON.stringify(c.got.statuses.slice(before)));
  assert.match(refused[0].message, /not a writable wire/);
});

test("a client publish reaches the device's pipe, packet by packet", { skip: missing || false }, async () => {
  const c = await connect({ token: OPERATOR });
  await waitFor(() => topicId(c.got, "sink/command_packets") !== undefined, "sink/command_packets advertised", 30000);
  const readSink = async () => {
    const id = `pipe-read-${c.got.params.length}`;
    c.client.getParameters(["sink/packets", "sink/last_packet"], id);
    const p = await waitFor(() => c.got.params.find((x) => x.id === id), id, 30000);
    return Object.fromEntries(p.parameters.map((x) => [x.name, x.value]));
  };
  const before = (await readSink())["sink/packets"];
  const channel = c.client.advertise({ topic: "sink/command_packets", encoding: "json",
    schemaName: "experimental.foxglove_sink.Sink.command_packets" });
  const send = (v) => c.client.sendMessage(channel, new TextEncoder().encode(JSON.stringify(v)));
  // Sent at once after the advertise: they wait for the pipe endpoint, in order, none lost.
  send({ value: [1, 2] });
  send([3, 4, 5]);  // the bare value works too
  await waitFor(async () => { const r = await readSink(); return r["sink/packets"] === before + 2 && JSON.stringify(r["sink/last_packet"]) === "[3,4,5]"; },
    `two packets at the device (${JSON.stringify(c.got.statuses)})`, 30000, 200);
  send({ value: "not numbers" });
  await waitFor(() => c.got.statuses.some((x) => x.level === 2 && /sink\/command_packets/.test(x.message)), "a status for a bad packet", 30000);
  send([6]);
  await waitFor(async () => { const r = await readSink(); return r["sink/packets"] === before + 3 && JSON.stringify(r["sink/last_packet"]) === "[6]"; },
    "the packet after the refused one", 30000, 200);
  // Unadvertised: the gateway's pipe endpoint for it ends; a new advertise works again.
  c.client.unadvertise(channel);
  const again = c.client.advertise({ topic: "sink/command_packets", encoding: "json", schemaName: "x" });
  c.client.sendMessage(again, new TextEncoder().encode("[7]"));
  await waitFor(async () => (await readSink())["sink/packets"] === before + 4, "a packet on the channel advertised again", 30000, 200);
  assert.equal(c.got.statuses.filter((x) => x.level === 2).length, 1, JSON.stringify(c.got.statuses));
});

test("time from the device's clock: time messages and receive times", { skip: missing || false }, async () => {
  const EPOCH = 978307200n * 1000000000n;  // command_sink.py's clock starts at 2001-01-01
  const DAY = 86400n * 1000000000n;
  const c = await connect({ token: OPERATOR });
  assert.ok(c.got.serverInfo.capabilities.includes("time"));
  await waitFor(() => c.got.times.length >= 3, "three time messages", 60000);
  const times = c.got.times.slice(0, 3);
  for (const t of times) assert.ok(t >= EPOCH && t < EPOCH + DAY, `a time on the device's clock: ${t}`);
  assert.ok(times[0] <= times[1] && times[1] <= times[2], `times in order: ${times}`);
  // messageData receive times are on the same clock (Foxglove compares them with its current time).
  await waitFor(() => topicId(c.got, "create/packets") !== undefined, "advertised", 30000);
  const sub = c.client.subscribe(topicId(c.got, "create/packets"));
  const m = await waitFor(() => c.got.messages.find((x) => x.subscriptionId === sub), "a value", 30000);
  assert.ok(m.timestamp >= EPOCH && m.timestamp < EPOCH + DAY, `a receive time on the device's clock: ${m.timestamp}`);
  assert.ok(m.timestamp >= times[0], `a receive time after the first time message: ${m.timestamp} < ${times[0]}`);
});

test("a viewer reads but may not set, call or publish; no login is refused", { skip: missing || false }, async () => {
  const v = await connect({ token: VIEWER });
  await waitFor(() => topicId(v.got, "create/packets") !== undefined && serviceId(v.got, "create/StartStreaming") !== undefined,
    "advertised to the viewer", 30000);
  const sub = v.client.subscribe(topicId(v.got, "create/packets"));
  await waitFor(() => v.got.messages.some((m) => m.subscriptionId === sub), "a value for the viewer", 30000);
  const refused = await callService(v, "create/StartStreaming", {}, 3);
  assert.equal(refused.op, "serviceCallFailure");
  assert.match(refused.message, /PermissionDenied|may not|not allowed/i);
  v.client.setParameters([{ name: "sink/label", value: "viewer-was-here" }], "v-set");
  await waitFor(() => v.got.statuses.some((x) => x.level === 2 && /not set: sink\/label: .*PermissionDenied/.test(x.message)),
    `setParameters refused (${JSON.stringify(v.got.statuses)})`, 30000);
  v.client.advertise({ topic: "sink/command", encoding: "json", schemaName: "x" });
  await waitFor(() => v.got.statuses.some((x) => x.level === 2 && /advertise: sink\/command:/.test(x.message)), "publish refused", 30000);
  v.client.advertise({ topic: "sink/command_packets", encoding: "json", schemaName: "x" });
  await waitFor(() => v.got.statuses.some((x) => x.level === 2 && /advertise: sink\/command_packets:/.test(x.message)),
    "publish to a pipe refused", 30000);
  v.client.getParameters(["sink/label"], "v-get");
  const p = await waitFor(() => v.got.params.find((x) => x.id === "v-get"), "the viewer's read", 30000);
  assert.notEqual(p.parameters[0].value, "viewer-was-here");

  const anon = await connect({});
  await waitFor(() => anon.got.closed, "the close of a connection without a login", 30000);
  assert.ok(anon.got.statuses.some((x) => x.level === 2 && /login required/.test(x.message)), JSON.stringify(anon.got.statuses));
  assert.equal(anon.got.serverInfo, null);
  const wrong = await connect({ token: OPERATOR, target: "/elsewhere" });
  await waitFor(() => wrong.got.closed, "the close of a connection on another path", 30000);
  assert.ok(wrong.got.statuses.some((x) => /path \/foxglove/.test(x.message)));
});

test("malformed and unknown messages get a status and nothing else", { skip: missing || false }, async () => {
  const c = await connect({ token: OPERATOR });
  await waitFor(() => topicId(c.got, "create/packets") !== undefined, "advertised", 30000);
  const statuses = () => c.got.statuses.filter((x) => x.level === 2).length;
  const cases = ["not json", "[1,2]", JSON.stringify({ op: "fly" }), JSON.stringify({ op: "subscribe", subscriptions: [{ id: 1, channelId: 99999 }] }),
    JSON.stringify({ op: "unsubscribe", subscriptionIds: [4242] }), "{".repeat(5000)];
  for (const [i, m] of cases.entries()) {
    c.ws.send(m);
    await waitFor(() => statuses() === i + 1, `the status for ${m.slice(0, 40)}`, 30000);
  }
  c.ws.send(Buffer.from([0x01, 0x05, 0, 0, 0, 0x7b]));  // publish on a channel never advertised
  c.ws.send(Buffer.from([0x09]));
  await waitFor(() => statuses() === cases.length + 2, "the statuses for bad binary messages", 30000);
  // The connection still works.
  const sub = c.client.subscribe(topicId(c.got, "create/packets"));
  await waitFor(() => c.got.messages.some((m) => m.subscriptionId === sub), "a value after the bad input", 30000);
  assert.equal(c.got.closed, false);
});

test("devices that restart are unadvertised and advertised again with the same ids", { skip: missing || false }, async () => {
  const c = await connect({ token: OPERATOR });
  await waitFor(() => topicId(c.got, "create/packets") !== undefined, "advertised", 30000);
  const before = topicId(c.got, "create/packets");
  const sub = c.client.subscribe(before);
  await waitFor(() => c.got.messages.some((m) => m.subscriptionId === sub), "a value before the restart", 30000);
  await demo.child.stop();
  await waitFor(() => c.got.unadvertised.includes(before) && topicId(c.got, "create/packets") === undefined, "create unadvertised", 60000);
  demo = await startProcess("rr-demo-devices", demoDevices, ["--listen", "127.0.0.1", "--port", String(demoPort)], "port", 60000);
  await waitFor(() => topicId(c.got, "create/packets") !== undefined, "create advertised again", 90000);
  assert.equal(topicId(c.got, "create/packets"), before);
  const again = c.client.subscribe(before);
  const n = c.got.messages.length;
  await waitFor(() => c.got.messages.slice(n).some((m) => m.subscriptionId === again), "a value after the restart", 60000);
});
