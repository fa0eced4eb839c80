// Frames off the page's thread (src/std/frame_decoder.js): the newest frame wins (one decoding, one
// waiting, the rest dropped), bad headers refused on the spot without reaching the decoder, data
// transferred to the Worker only when it is a whole buffer of its own, the page taking over when the
// Worker fails; and which values hold pictures (src/views/image_set.js) by their descriptors.
import { test } from "node:test";
import assert from "node:assert/strict";
import { FrameDecoder } from "../src/std/frame_decoder.js";
import { STANDARD_IMAGE_ENCODINGS as E } from "../src/std/image_encodings.js";
import { RobdefOutline } from "../src/std/robdef_outline.js";
import { standardDescriber } from "../src/std/standard.js";
import { imageKind, hasImages, picturesOf } from "../src/views/image_set.js";
import { frameTime, ageWords } from "../src/views/frame_view.js";
import { standardDefinitions, SKIP_REASON } from "./std_fixtures.mjs";

const rgb = (n = 1) => ({ image_info: { width: n, height: 1, step: 3 * n, encoding: E.rgb888 }, data: new Uint8Array(3 * n) });
const tick = () => new Promise((r) => setImmediate(r));

/** A decode() whose calls wait until the test resolves them. */
function manualDecode() {
  const calls = [];
  const decode = (value, options) => new Promise((resolve) => calls.push({ value, options, resolve }));
  return { calls, decode };
}

test("the newest frame wins: one decoding, one waiting, the frames between dropped", async () => {
  const { calls, decode } = manualDecode();
  const results = [];
  const dec = new FrameDecoder({ Worker: null, decode, onResult: (r, meta) => results.push([r.ok, meta.seq, meta.tag]) });
  assert.equal(dec.inWorker, false);
  for (let i = 1; i <= 5; i++) assert.equal(dec.submit(rgb(i), {}, { tag: i }), null);
  await tick();
  assert.equal(calls.length, 1, "one frame decoding");
  assert.equal(calls[0].value.image_info.width, 1);
  assert.equal(calls[0].options.compressed, false, "raw: image_info.encoding tells");
  calls[0].resolve({ ok: true, width: 1 });
  await tick();
  assert.equal(calls.length, 2, "then the newest waiting one");
  assert.equal(calls[1].value.image_info.width, 5);
  calls[1].resolve({ ok: true, width: 5 });
  await tick();
  assert.deepEqual(results, [[true, 1, 1], [true, 5, 5]]);
  assert.deepEqual(dec.stats, { submitted: 5, decoded: 2, failed: 0, dropped: 3, refused: 0 });
});

test("bad headers are refused at once and never reach the decoder; a failed decode is a result", async () => {
  const { calls, decode } = manualDecode();
  const results = [];
  const dec = new FrameDecoder({ Worker: null, decode, onResult: (r, meta) => results.push([r.ok ? "ok" : r.error.code, meta.seq]) });
  const short = rgb(4);
  short.data = short.data.subarray(0, 5);
  assert.equal(dec.submit(short).error.code, "data_too_short");
  assert.equal(dec.submit({ image_info: { width: 4, height: 1, step: 12, encoding: 0x1234 }, data: new Uint8Array(12) }).error.code, "unknown_encoding");
  assert.equal(dec.submit({ image_info: { width: 2, height: 2, step: 0, encoding: E.compressed }, data: Uint8Array.of(1, 2, 3) }).error.code, "unknown_format");
  assert.equal(dec.submit(null).error.code, "not_an_image");
  // a flood of bad frames: none decoded, none queued
  for (let i = 0; i < 1000; i++) dec.submit(short);
  await tick();
  assert.equal(calls.length, 0);
  assert.equal(dec.stats.refused, 1004);
  // a JPEG that the decoder cannot read: its error comes back as a result
  dec.submit({ image_info: { width: 2, height: 2, step: 0, encoding: E.compressed }, data: Uint8Array.of(0xff, 0xd8, 0xff, 0, 1) });
  await tick();
  assert.equal(calls.length, 1);
  assert.equal(calls[0].options.compressed, true);
  calls[0].resolve({ ok: false, error: { code: "decode_failed", message: "corrupt" } });
  await tick();
  assert.deepEqual(results.slice(0, 4), [["data_too_short", 1], ["unknown_encoding", 2], ["unknown_format", 3], ["not_an_image", 4]]);
  assert.deepEqual(results.at(-1), ["decode_failed", 1005]);
  // a decoder that throws, and a handler that throws, do not reach the caller
  const quiet = console.error;
  console.error = () => {};
  try {
    const loud = new FrameDecoder({ Worker: null, decode: () => { throw new Error("boom"); }, onResult: () => { throw new Error("handler"); } });
    assert.doesNotThrow(() => loud.submit(rgb()));
    assert.doesNotThrow(() => loud.submit(null));
    await tick();
    assert.equal(loud.stats.failed, 1);
  } finally {
    console.error = quiet;
  }
});

/** A stand-in for Worker: records what is posted and transferred; the test answers or fails it. */
class FakeWorker {
  static last = null;
  constructor(url, options) {
    this.url = String(url);
    this.options = options;
    this.posted = [];
    FakeWorker.last = this;
  }
  postMessage(message, transfer) { this.posted.push({ message, transfer }); }
  answer(result) { this.onmessage({ data: { id: this.posted.at(-1).message.id, result } }); }
  terminate() { this.terminated = true; }
}

test("in a Worker: whole buffers transferred, views copied; the page takes over when the Worker fails", async () => {
  const results = [];
  const dec = new FrameDecoder({ Worker: FakeWorker, onResult: (r) => results.push(r), decode: async () => ({ ok: true, here: true }) });
  const w = FakeWorker.last;
  assert.ok(dec.inWorker);
  assert.match(w.url, /image_worker\.js$/);
  assert.equal(w.options.type, "module");
  const own = rgb(2);
  dec.submit(own, { encodings: [{ name: "rgb888", value: E.rgb888 }] });
  const first = w.posted[0];
  assert.equal(first.transfer[0], own.data.buffer, "the value's own buffer is transferred");
  assert.deepEqual(first.message.image_info, { width: 2, height: 1, step: 6, encoding: E.rgb888 });
  assert.equal(first.message.compressed, false);
  w.answer({ ok: true, width: 2 });
  // a view into a larger buffer (a value cut out of something bigger) is copied, its buffer left alone
  const big = new Uint8Array(100);
  const view = { image_info: { width: 1, height: 1, step: 3, encoding: E.rgb888 }, data: big.subarray(10, 13) };
  dec.submit(view);
  assert.notEqual(w.posted[1].transfer[0], big.buffer);
  assert.equal(w.posted[1].message.data.length, 3);
  // with transfer: false nothing of the caller's is detached
  const keep = new FrameDecoder({ Worker: FakeWorker, transfer: false, onResult: () => {} });
  const mine = rgb(1);
  keep.submit(mine);
  assert.notEqual(FakeWorker.last.posted[0].transfer[0], mine.data.buffer);
  // the Worker fails while decoding: that frame is reported lost, the next one decoded on the page
  dec.submit(rgb(3));
  w.onerror({ preventDefault() {} });
  assert.ok(w.terminated);
  assert.equal(dec.inWorker, false);
  assert.equal(results.at(-1).error.code, "decode_failed");
  dec.submit(rgb(4));
  await tick();
  assert.deepEqual(results.at(-1), { ok: true, here: true });
});

test("frame times and ages", () => {
  const clocks = [{ name: "default", value: 1 }, { name: "sim_clock_scaled", value: 10 }];
  const v = (clock_type, seconds) => ({ image_info: { data_header: { ts: { clock_info: { clock_type }, seconds, nanoseconds: 500000000 } } } });
  assert.deepEqual(frameTime(v(1, 100n), clocks), { seconds: 100.5, comparable: true });
  assert.deepEqual(frameTime(v(10, 100n), clocks), { seconds: 100.5, comparable: false });
  assert.equal(frameTime(v(1, 0n, 0), clocks)?.seconds, 0.5);
  assert.equal(frameTime({ image_info: { data_header: null } }), null);
  assert.equal(frameTime({ image_info: { data_header: { ts: { seconds: 0, nanoseconds: 0 } } } }), null, "unset");
  assert.equal(frameTime(null), null);
  assert.equal(ageWords(0.08), "80 ms old");
  assert.equal(ageWords(2.5), "2.5 s old");
  assert.equal(ageWords(-1.2), "1.2 s ahead of this page's clock");
});

test("which values hold pictures, by their descriptors", (t) => {
  const defs = standardDefinitions();
  if (!defs) { t.skip(SKIP_REASON); return; }
  const types = standardDescriber(new RobdefOutline(defs));
  const I = "com.robotraconteur.imaging";
  const image = types.describe("Image", I), compressed = types.describe("CompressedImage", I);
  assert.deepEqual([imageKind(image), imageKind(compressed)], ["image", "compressed"]);
  assert.equal(imageKind(types.describe("ImagePart", I)), null, "parts are not pictures");
  const all = types.describe("Image{int32}", I);
  assert.ok(hasImages(all) && !imageKind(all));
  const frame = (n) => ({ image_info: { width: n }, data: new Uint8Array(n) });
  const map = new Map([[3, frame(3)], [1, frame(1)], [2, null]]);
  assert.deepEqual(picturesOf(map, all).map(([k, v, kind]) => [k, v.image_info.width, kind]), [["1", 1, "image"], ["3", 3, "image"]]);
  assert.deepEqual(picturesOf([frame(1), frame(2)], types.describe("CompressedImage{list}", I)).map(([k, , kind]) => [k, kind]),
    [["0", "compressed"], ["1", "compressed"]]);
  assert.equal(picturesOf(frame(1), image)[0][0], "");
  assert.deepEqual(picturesOf(frame(1), types.describe("CameraInfo", I)), []);
  assert.deepEqual(picturesOf(null, image), []);
  // MultiCamera's camera map by string keys, at most 8 pictures
  const many = Object.fromEntries(Array.from({ length: 12 }, (_, i) => [`cam${i}`, frame(1)]));
  assert.equal(picturesOf(many, types.describe("Image{string}", I)).length, 8);
  // an older ImageInfo layout (no step): no renderer, no pictures, the generic view
  const old = { ...defs };
  old["com.robotraconteur.image"] = defs["com.robotraconteur.image"].replace(/\n\s*field uint32 step\n/, "\n");
  const oldImage = standardDescriber(new RobdefOutline(old)).describe("Image", I);
  assert.match(oldImage.mismatch, /step/);
  assert.equal(hasImages(oldImage), false);
});
