// The pure parts of the Record control and the replay timeline (src/record/recording_api.js,
// docs/recording.md "JSON API" and "Replay"): request bodies, the gateway's refusals, formats.
import { test } from "node:test";
import assert from "node:assert/strict";
import {
  recordableMembers, parseMemberPaths, recordingBody, formatBytes, formatSeconds, timeSpan, recordingsOf, replayControlBody,
  apiRequest, ApiRequestError, startRecording, stopRecording, controlReplay,
} from "../src/record/recording_api.js";

const answer = (status, body) => ({ ok: status >= 200 && status < 300, status, json: async () => { if (body === undefined) throw new SyntaxError("no body"); return body; } });

test("recordable members: wires, pipes, events, properties; not functions, objrefs, callbacks, memories", () => {
  const members = [
    { name: "packets", kind: "pipe" }, { name: "Drive", kind: "function" }, { name: "Bump", kind: "event" },
    { name: "DistanceTraveled", kind: "property" }, { name: "state", kind: "wire" }, { name: "sub", kind: "objref" },
    { name: "cb", kind: "callback" }, { name: "mem", kind: "memory" },
  ];
  assert.deepEqual(recordableMembers(members).map((m) => m.name), ["packets", "Bump", "DistanceTraveled", "state"]);
  assert.deepEqual(recordableMembers(undefined), []);
});

test("the POST api/recordings body: members, encodings, directory only when given", () => {
  assert.deepEqual(recordingBody({ device: "create", members: ["packets"] }),
    { device: "create", members: ["packets"], encoding: ["json", "robotraconteur"] });
  assert.deepEqual(recordingBody({ device: "create", members: ["a", "b"], encoding: "json", directory: "  /tmp/rec " }),
    { device: "create", members: ["a", "b"], encoding: ["json"], directory: "/tmp/rec" });
  assert.deepEqual(recordingBody({ device: "d", members: ["a"], encoding: "robotraconteur", directory: " " }).encoding, ["robotraconteur"]);
  assert.throws(() => recordingBody({ device: "d", members: [] }), /at least one member/);
  assert.throws(() => recordingBody({ device: "d", members: ["a"], encoding: "cbor" }), /unknown encoding "cbor"/);
});

test("sizes and durations for people", () => {
  assert.equal(formatBytes(0), "0 B");
  assert.equal(formatBytes(1023), "1023 B");
  assert.equal(formatBytes(1536), "1.50 KiB");
  assert.equal(formatBytes(12.5 * 1024 * 1024), "12.5 MiB");
  assert.equal(formatBytes(-1), "–");
  assert.equal(formatBytes(undefined), "–");
  assert.equal(formatSeconds(0), "0:00.0");
  assert.equal(formatSeconds(4.26), "0:04.3");
  assert.equal(formatSeconds(61.5), "1:01.5");
  assert.equal(formatSeconds(3723.25), "1:02:03.3");
  assert.equal(formatSeconds(null), "–");
});

test("a file's time span from start_ns (beyond 2^53) and its duration", () => {
  const span = timeSpan("1764172800123456789", 2.5);
  assert.deepEqual(span, { start: "2025-11-26T16:00:00.123Z", end: "2025-11-26T16:00:02.623Z" });
  assert.equal(timeSpan(1764172800123456789, 0).start, "2025-11-26T16:00:00.123Z");
});

test("the recordings of one device, newest first", () => {
  const list = { recordings: [{ id: 1, device: "create" }, { id: 2, device: "cam" }, { id: 3, device: "create" }] };
  assert.deepEqual(recordingsOf(list, "create").map((r) => r.id), [3, 1]);
  assert.deepEqual(recordingsOf({}, "create"), []);
});

test("the POST api/replays body: only what changes, checked", () => {
  assert.deepEqual(replayControlBody({ state: "paused" }), { state: "paused" });
  assert.deepEqual(replayControlBody({ position_s: 1.5, speed: 2, loop: 1, state: "playing" }), { position_s: 1.5, speed: 2, loop: true, state: "playing" });
  assert.throws(() => replayControlBody({ speed: 0 }), /bad speed 0/);
  assert.throws(() => replayControlBody({ position_s: -1 }), /bad position/);
  assert.throws(() => replayControlBody({ state: "stopped" }), /bad state stopped/);
});

test("requests: relative URLs, JSON bodies, the gateway's error message on a refusal", async () => {
  const asked = [];
  const fake = (status, body) => async (url, init) => { asked.push({ url, method: init.method, body: init.body && JSON.parse(init.body) }); return answer(status, body); };
  assert.deepEqual(await startRecording({ device: "d", members: ["a"] }, fake(201, { id: 4, state: "recording" })), { id: 4, state: "recording" });
  await stopRecording(4, fake(200, { id: 4, state: "stopped" }));
  await controlReplay("my replay", { speed: 2 }, fake(200, {}));
  assert.deepEqual(asked, [
    { url: "api/recordings", method: "POST", body: { device: "d", members: ["a"] } },
    { url: "api/recordings/4/stop", method: "POST", body: {} },
    { url: "api/replays/my%20replay", method: "POST", body: { speed: 2 } },
  ]);
  const refused = fake(507, { error: { name: "RobotRaconteur.IOError", message: "record: /proc/rec: Permission denied" } });
  await assert.rejects(startRecording({ device: "d", members: ["a"] }, refused),
    (e) => e instanceof ApiRequestError && e.status === 507 && e.message === "record: /proc/rec: Permission denied");
  await assert.rejects(apiRequest("GET", "api/replays", undefined, fake(502)), /GET api\/replays: HTTP 502/);
});

test("members below the root as typed: split on commas, spaces and new lines outside brackets", () => {
  assert.deepEqual(parseMemberPaths("Webcams[0].FrameStream, Webcams[1].Name"), ["Webcams[0].FrameStream", "Webcams[1].Name"]);
  assert.deepEqual(parseMemberPaths(" a.b\n\n c[x, y].d ,,"), ["a.b", "c[x, y].d"]);
  assert.deepEqual(parseMemberPaths(""), []);
  assert.deepEqual(parseMemberPaths(undefined), []);
});
