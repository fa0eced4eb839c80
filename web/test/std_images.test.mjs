// Image decoding of the standard types (src/std/image_decode.js, bayer.js, colormap.js,
// compressed_image.js, image_bitmap.js): every raw ImageEncoding against pixel values the test works
// out from how it packed them, the bad frames one by one, compressed formats by magic bytes.
import { test } from "node:test";
import assert from "node:assert/strict";
import { RobdefOutline } from "../src/std/robdef_outline.js";
import { decodeImage, checkImage } from "../src/std/image_decode.js";
import { STANDARD_IMAGE_ENCODINGS, PIXEL_FORMATS } from "../src/std/image_encodings.js";
import { halfToNumber } from "../src/std/float16.js";
import { compressedFormat, checkCompressedImage } from "../src/std/compressed_image.js";
import { imageToBitmap, isCompressedEncoding } from "../src/std/image_bitmap.js";
import { standardDefinitions, SKIP_REASON } from "./std_fixtures.mjs";

const E = STANDARD_IMAGE_ENCODINGS;

function random(seed) {
  return () => {
    seed = (seed + 0x6d2b79f5) | 0;
    let t = Math.imul(seed ^ (seed >>> 15), 1 | seed);
    t = (t + Math.imul(t ^ (t >>> 7), 61 | t)) ^ t;
    return ((t ^ (t >>> 14)) >>> 0) / 4294967296;
  };
}

/**
 * An Image value of `encoding`: rows of `bytes` per pixel plus `pad` bytes, the data a view at an odd
 * offset of a larger buffer (as values cut out of a message are); `write(dv, offset, x, y)` packs a pixel.
 */
function makeImage(encoding, width, height, bytes, write, pad = 3) {
  const step = width * bytes + pad;
  const buffer = new ArrayBuffer(height * step + 5);
  const data = new Uint8Array(buffer, 1, height * step);
  data.fill(0xee);  // padding must not show
  const dv = new DataView(buffer, 1);
  for (let y = 0; y < height; y++) for (let x = 0; x < width; x++) write(dv, y * step + x * bytes, x, y);
  return { image_info: { width, height, step, encoding: E[encoding], data_header: null, extended: null }, data };
}

function pixel(result, x, y) {
  const o = (y * result.width + x) * 4;
  return Array.from(result.data.subarray(o, o + 4));
}

function assertPixels(result, width, height, expected) {
  assert.equal(result.ok, true, JSON.stringify(result.error));
  assert.equal(result.width, width);
  assert.equal(result.height, height);
  assert.ok(result.data instanceof Uint8ClampedArray);
  assert.equal(result.data.length, width * height * 4);
  for (let y = 0; y < height; y++) for (let x = 0; x < width; x++) {
    assert.deepEqual(pixel(result, x, y), expected(x, y), `pixel (${x}, ${y})`);
  }
}

test("the encoding numbers are those of the standard definition's ImageEncoding", (t) => {
  const defs = standardDefinitions();
  if (!defs) return t.skip(SKIP_REASON);
  const values = new RobdefOutline(defs).enumOf("ImageEncoding", "com.robotraconteur.image");
  assert.deepEqual(Object.fromEntries(values.map((v) => [v.name, v.value])), { ...E });
  const raw = values.map((v) => v.name).filter((n) => !["unknown", "freeform", "compressed", "other"].includes(n));
  assert.deepEqual(raw.sort(), Object.keys(PIXEL_FORMATS).sort());
});

test("8-bit colour: rgb888, rgba8888, bgr888, bgra8888", () => {
  const w = 5, h = 3;
  const rnd = random(1);
  const colours = Array.from({ length: w * h }, () => [0, 0, 0, 0].map(() => Math.floor(rnd() * 256)));
  const c = (x, y) => colours[y * w + x];
  const cases = {
    rgb888: [3, (p) => [p[0], p[1], p[2]], (p) => [p[0], p[1], p[2], 255]],
    rgba8888: [4, (p) => p, (p) => p],
    bgr888: [3, (p) => [p[2], p[1], p[0]], (p) => [p[0], p[1], p[2], 255]],
    bgra8888: [4, (p) => [p[2], p[1], p[0], p[3]], (p) => p],
  };
  for (const [name, [bytes, packed, expected]] of Object.entries(cases)) {
    const img = makeImage(name, w, h, bytes, (dv, o, x, y) => packed(c(x, y)).forEach((b, i) => dv.setUint8(o + i, b)));
    const r = decodeImage(img);
    assert.equal(r.encoding, name);
    assertPixels(r, w, h, (x, y) => expected(c(x, y)));
  }
});

test("16-bit colour: rgba16_16_16_16 and bgra16_16_16_16 keep the high byte of each little-endian sample", () => {
  const w = 4, h = 2;
  const rnd = random(2);
  const colours = Array.from({ length: w * h }, () => [0, 0, 0, 0].map(() => Math.floor(rnd() * 65536)));
  const c = (x, y) => colours[y * w + x];
  for (const [name, order] of [["rgba16_16_16_16", [0, 1, 2, 3]], ["bgra16_16_16_16", [2, 1, 0, 3]]]) {
    const img = makeImage(name, w, h, 8, (dv, o, x, y) => order.forEach((k, i) => dv.setUint16(o + 2 * i, c(x, y)[k], true)));
    assertPixels(decodeImage(img), w, h, (x, y) => c(x, y).map((v) => Math.floor(v / 256)));
  }
});

test("mono8, mono16, mono32: grey from the highest byte", () => {
  const w = 6, h = 2;
  const rnd = random(3);
  for (const [name, bytes, max, set] of [
    ["mono8", 1, 256, "setUint8"], ["mono16", 2, 65536, "setUint16"], ["mono32", 4, 4294967296, "setUint32"]]) {
    const values = Array.from({ length: w * h }, () => Math.floor(rnd() * max));
    values[0] = max - 1; values[1] = 0;
    const img = makeImage(name, w, h, bytes, (dv, o, x, y) => dv[set](o, values[y * w + x], true));
    assertPixels(decodeImage(img), w, h, (x, y) => {
      const g = Math.floor(values[y * w + x] / (max / 256));
      return [g, g, g, 255];
    });
  }
});

test("mono_f16, mono_f32, mono_f64: 0..1 to 0..255, clamped, NaN black; other ranges by option", () => {
  // half floats by their bits: 0, 1, 0.5, 0.25, -1, +Inf, NaN, the smallest subnormal, 0.333251953125
  const halves = [0x0000, 0x3c00, 0x3800, 0x3400, 0xbc00, 0x7c00, 0x7e00, 0x0001, 0x3555];
  assert.deepEqual(halves.map(halfToNumber), [0, 1, 0.5, 0.25, -1, Infinity, NaN, 2 ** -24, 0.333251953125]);
  const greys = [0, 255, 128, 64, 0, 255, 0, 0, 85];
  const f16 = makeImage("mono_f16", 9, 1, 2, (dv, o, x) => dv.setUint16(o, halves[x], true));
  assertPixels(decodeImage(f16), 9, 1, (x) => [greys[x], greys[x], greys[x], 255]);

  const values = [0, 1, 0.5, 0.25, -1, Infinity, NaN, 2, 0.1];
  const expected = [0, 255, 128, 64, 0, 255, 0, 255, 26];
  for (const [name, bytes, set] of [["mono_f32", 4, "setFloat32"], ["mono_f64", 8, "setFloat64"]]) {
    const img = makeImage(name, 9, 1, bytes, (dv, o, x) => dv[set](o, values[x], true));
    assertPixels(decodeImage(img), 9, 1, (x) => [expected[x], expected[x], expected[x], 255]);
  }
  const wide = makeImage("mono_f32", 3, 1, 4, (dv, o, x) => dv.setFloat32(o, [-10, 0, 10][x], true));
  assertPixels(decodeImage(wide, { floatRange: { min: -10, max: 10 } }), 3, 1, (x) => {
    const g = [0, 128, 255][x];
    return [g, g, g, 255];
  });
});

// The colour map by hand: stops at 0, 32, 96, 160, 224, 255 and halfway between them
const JET = {
  0: [0, 0, 143], 32: [0, 0, 255], 64: [0, 128, 255], 96: [0, 255, 255], 128: [128, 255, 128],
  160: [255, 255, 0], 192: [255, 128, 0], 224: [255, 0, 0], 255: [128, 0, 0],
};
const STOPS = Object.keys(JET).map(Number);

test("depth_*: colour map over the frame's range of valid depths, range reported, invalid pixels black", () => {
  // pixels: depth = base + one of the map's stop indices, then a 0 (no depth)
  const cases = [
    ["depth_u16", 2, "setUint16", 1000], ["depth_i16", 2, "setInt16", -1255], ["depth_u32", 4, "setUint32", 70000],
    ["depth_i32", 4, "setInt32", -100000], ["depth_f32", 4, "setFloat32", 1000], ["depth_f64", 8, "setFloat64", 0.5],
    ["depth_u64", 8, "setBigUint64", 2 ** 40], ["depth_i64", 8, "setBigInt64", -(2 ** 40)],
  ];
  for (const [name, bytes, set, base] of cases) {
    const w = STOPS.length + 1;
    const depth = (x) => (x < STOPS.length ? base + STOPS[x] : 0);
    const img = makeImage(name, w, 2, bytes, (dv, o, x) => {
      const v = set.includes("Big") ? BigInt(depth(x)) : depth(x);
      dv[set](o, v, true);
    });
    const r = decodeImage(img);
    assertPixels(r, w, 2, (x) => (x < STOPS.length ? [...JET[STOPS[x]], 255] : [0, 0, 0, 255]));
    assert.deepEqual(r.range, { min: base, max: base + 255 }, name);
  }
  // NaN and infinities are no depth either; a fixed range clamps
  const f = makeImage("depth_f32", 5, 1, 4, (dv, o, x) => dv.setFloat32(o, [1, NaN, Infinity, 3, 5][x], true));
  const r = decodeImage(f);
  assert.deepEqual(r.range, { min: 1, max: 5 });
  assert.deepEqual([0, 1, 2, 3, 4].map((x) => pixel(r, x, 0)),
    [[...JET[0], 255], [0, 0, 0, 255], [0, 0, 0, 255], [...JET[128], 255], [...JET[255], 255]]);
  const fixed = decodeImage(f, { depthRange: { min: 3, max: 4 } });
  assert.deepEqual(fixed.range, { min: 3, max: 4 });
  assert.deepEqual([pixel(fixed, 0, 0), pixel(fixed, 4, 0)], [[...JET[0], 255], [...JET[255], 255]]);
  // no valid depth at all: black, no range
  const none = decodeImage(makeImage("depth_u16", 2, 1, 2, (dv, o) => dv.setUint16(o, 0, true)));
  assert.equal(none.range, null);
  assert.deepEqual(pixel(none, 1, 0), [0, 0, 0, 255]);
});

const PATTERNS = { bayer_rggb8888: "rggb", bayer_bggr8888: "bggr", bayer_gbrg8888: "gbrg", bayer_grbg8888: "grbg" };

test("bayer_*: bilinear demosaicing (interior pixels against the textbook formulas)", () => {
  const w = 8, h = 6;
  const rnd = random(5);
  const raw = Array.from({ length: w * h }, () => Math.floor(rnd() * 256));
  const at = (x, y) => raw[y * w + x];
  const mean = (...v) => Math.round(v.reduce((a, b) => a + b, 0) / v.length);
  for (const [name, pattern] of Object.entries(PATTERNS)) {
    const colour = (x, y) => pattern[(y % 2) * 2 + (x % 2)];
    const img = makeImage(name, w, h, 1, (dv, o, x, y) => dv.setUint8(o, at(x, y)));
    const r = decodeImage(img);
    assert.equal(r.ok, true);
    for (let y = 1; y < h - 1; y++) for (let x = 1; x < w - 1; x++) {
      const cross = mean(at(x - 1, y), at(x + 1, y), at(x, y - 1), at(x, y + 1));
      const diagonal = mean(at(x - 1, y - 1), at(x + 1, y - 1), at(x - 1, y + 1), at(x + 1, y + 1));
      const across = mean(at(x - 1, y), at(x + 1, y));
      const upDown = mean(at(x, y - 1), at(x, y + 1));
      let rgb;
      const own = at(x, y);
      if (colour(x, y) === "r") rgb = [own, cross, diagonal];
      else if (colour(x, y) === "b") rgb = [diagonal, cross, own];
      else if (colour(x + 1, y) === "r") rgb = [across, own, upDown];  // green in a red row
      else rgb = [upDown, own, across];                                 // green in a blue row
      assert.deepEqual(pixel(r, x, y), [...rgb, 255], `${name} (${x}, ${y})`);
    }
  }
});

test("bayer_*: a flat colour comes back everywhere, borders included; a 2×2 mosaic by hand", () => {
  const flat = { r: 10, g: 200, b: 50 };
  for (const [name, pattern] of Object.entries(PATTERNS)) {
    const img = makeImage(name, 5, 3, 1, (dv, o, x, y) => dv.setUint8(o, flat[pattern[(y % 2) * 2 + (x % 2)]]));
    assertPixels(decodeImage(img), 5, 3, () => [10, 200, 50, 255]);
  }
  // R 100, G 50 / G 70, B 31: each pixel's missing colours are the means of the others present
  const tiny = makeImage("bayer_rggb8888", 2, 2, 1, (dv, o, x, y) => dv.setUint8(o, [[100, 50], [70, 31]][y][x]));
  assertPixels(decodeImage(tiny), 2, 2, (x, y) => [
    [[100, 60, 31, 255], [100, 50, 31, 255]],
    [[100, 70, 31, 255], [100, 60, 31, 255]],
  ][y][x]);
});

test("the device's own ImageEncoding numbers are used when given", () => {
  const img = makeImage("rgb888", 1, 1, 3, (dv, o) => [1, 2, 3].forEach((b, i) => dv.setUint8(o + i, b)));
  img.image_info.encoding = 7;
  assert.equal(decodeImage(img).error.code, "unknown_encoding");
  const r = decodeImage(img, { encodings: [{ name: "unknown", value: 0 }, { name: "bgr888", value: 7 }] });
  assert.deepEqual(pixel(r, 0, 0), [3, 2, 1, 255]);
  img.image_info.encoding = "rgb888";  // package users may name it
  assert.deepEqual(pixel(decodeImage(img), 0, 0), [1, 2, 3, 255]);
});

test("an output buffer of the right size is reused", () => {
  const img = makeImage("mono8", 2, 2, 1, (dv, o, x) => dv.setUint8(o, x * 100));
  const out = new Uint8ClampedArray(16);
  assert.equal(decodeImage(img, { out }).data, out);
  assert.notEqual(decodeImage(img, { out: new Uint8ClampedArray(4) }).data.length, 4);
});

/** data that counts reads of its pixels (a frame refused from its header reads none) */
function counting(bytes) {
  const counter = { reads: 0 };
  const proxy = new Proxy(bytes, {
    get(target, key) {
      if (typeof key === "string" && /^\d+$/.test(key)) counter.reads++;
      const v = Reflect.get(target, key, target);
      return typeof v === "function" ? v.bind(target) : v;
    },
  });
  return { proxy, counter };
}

test("bad frames, one by one: an error result from the header, no exception, no pixel read", () => {
  const good = () => makeImage("rgb888", 4, 3, 3, (dv, o) => dv.setUint8(o, 1), 0);
  const cases = [
    ["data_too_short", (v) => { v.data = v.data.subarray(0, 4 * 3 * 3 - 1); }],
    ["step_too_small", (v) => { v.image_info.step = 11; }],
    ["unknown_encoding", (v) => { v.image_info.encoding = 0x1234; }],
    ["unknown_encoding", (v) => { v.image_info.encoding = "rgb999"; }],
    ["not_raw", (v) => { v.image_info.encoding = E.compressed; }],
    ["not_raw", (v) => { v.image_info.encoding = E.freeform; }],
    ["zero_size", (v) => { v.image_info.width = 0; }],
    ["zero_size", (v) => { v.image_info.height = 0; }],
    ["not_an_image", (v) => { v.image_info.width = -1; }],
    ["not_an_image", (v) => { v.image_info.step = 1.5; }],
    ["not_an_image", (v) => { delete v.image_info; }],
    ["bad_data", (v) => { v.data = Array.from(v.data); }],
    ["bad_data", (v) => { v.data = new Uint16Array(100); }],
  ];
  for (const [code, spoil] of cases) {
    const v = good();
    spoil(v);
    let counter = { reads: 0 };
    if (v.data instanceof Uint8Array) ({ proxy: v.data, counter } = counting(v.data));
    const r = decodeImage(v);
    assert.equal(r.ok, false, code);
    assert.equal(r.error.code, code, `${code}: ${r.error.message}`);
    assert.equal(typeof r.error.message, "string");
    assert.equal(counter.reads, 0, `${code}: pixels read`);
  }
  for (const v of [undefined, null, 42, "image", {}, { image_info: null, data: new Uint8Array(1) }]) {
    assert.equal(decodeImage(v).error.code, "not_an_image");
  }
  // a huge claimed size with few bytes is refused before anything is allocated for it
  const huge = { image_info: { width: 100000, height: 100000, step: 300000, encoding: E.rgb888 }, data: new Uint8Array(10) };
  assert.equal(checkImage(huge).error.code, "data_too_short");
  assert.match(decodeImage(huge).error.message, /10 bytes.*100000 rows of step 300000/);
  // the step check gives the row size in bytes
  const narrow = good();
  narrow.image_info.step = 11;
  assert.match(decodeImage(narrow).error.message, /step 11 is less than a row of 4 rgb888 pixels \(12 bytes\)/);
});

test("a step in pixels (what a FLIR-style mono16 driver sends): read as rows of whole pixels, with a note", () => {
  // mono16, 5×3, step = width = 5 (in pixels), data exactly 3 rows of 5 two-byte samples
  const width = 5, height = 3;
  const data = new Uint8Array(width * height * 2);
  for (let i = 0; i < width * height; i++) { data[2 * i] = 0x11; data[2 * i + 1] = 10 * i; }
  const v = { image_info: { width, height, step: width, encoding: E.mono16 }, data };
  const r = decodeImage(v);
  assert.equal(r.ok, true, r.error?.message);
  assert.match(r.note, /step 5 read as pixels: rows of 10 bytes/);
  for (let i = 0; i < width * height; i++) assert.equal(r.data[4 * i], 10 * i, `pixel ${i}: its high byte`);
  // the same step with data for a real step of 5 bytes (too short for whole rows) is still refused
  assert.equal(decodeImage({ ...v, data: data.subarray(0, 15) }).error.code, "step_too_small");
  // one byte more than whole rows: not a step in pixels either
  assert.equal(decodeImage({ ...v, data: new Uint8Array(31) }).error.code, "step_too_small");
  // one-byte encodings never need it: step = width is a whole row there
  assert.equal(decodeImage({ image_info: { width, height, step: width, encoding: E.mono8 }, data: new Uint8Array(15) }).note, undefined);
});

const JPEG = Uint8Array.of(0xff, 0xd8, 0xff, 0xe0, 0, 0x10, 0x4a, 0x46, 0x49, 0x46);
const PNG = Uint8Array.of(0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0, 0, 0, 13);
const bytes = (s, ...more) => Uint8Array.from([...Array.from(s, (ch) => ch.charCodeAt(0)), ...more]);

test("CompressedImage: the format from its magic bytes", () => {
  const formats = [
    [JPEG, "jpeg", true], [PNG, "png", true], [bytes("GIF89a", 1, 0), "gif", false], [bytes("GIF87a"), "gif", false],
    [bytes("RIFF", 0, 0, 0, 0, ...bytes("WEBPVP8 ")), "webp", false], [bytes("BM", 0, 0), "bmp", false],
    [Uint8Array.of(0x49, 0x49, 0x2a, 0), "tiff", false], [Uint8Array.of(0x4d, 0x4d, 0, 0x2a), "tiff", false],
    [Uint8Array.of(0xff, 0x4f, 0xff, 0x51), "jpeg2000", false], [bytes("qoif", 0, 0), "qoi", false],
    [Uint8Array.of(0, 0, 0, 0x1c, ...bytes("ftypavif")), "avif", false],
  ];
  for (const [data, name, drawable] of formats) {
    assert.deepEqual([compressedFormat(data)?.name, compressedFormat(data)?.drawable], [name, drawable], name);
    const c = checkCompressedImage({ image_info: { width: 640, height: 480, step: 0, encoding: E.compressed }, data });
    assert.equal(c.ok, drawable, name);
    if (drawable) assert.deepEqual([c.width, c.height, c.format.mime], [640, 480, `image/${name}`]);
    else assert.equal(c.error.code, "not_drawable");
  }
  assert.equal(compressedFormat(Uint8Array.of(0xff, 0xd8)), null);  // too short for JPEG's magic
  assert.equal(checkCompressedImage({ data: Uint8Array.of(1, 2, 3, 4, 5) }).error.code, "unknown_format");
  assert.match(checkCompressedImage({ data: Uint8Array.of(1, 2, 3, 4, 5) }).error.message, /01 02 03 04/);
  assert.equal(checkCompressedImage({ data: new Uint8Array(0) }).error.code, "empty");
  assert.equal(checkCompressedImage({ data: [0xff, 0xd8, 0xff] }).error.code, "bad_data");
  assert.equal(checkCompressedImage(null).error.code, "not_an_image");
});

test("imageToBitmap: compressed bytes to createImageBitmap as a Blob, raw frames as ImageData; errors resolve", async () => {
  const calls = [];
  const createImageBitmap = async (source) => {
    calls.push(source);
    if (source instanceof Blob) {
      const b = new Uint8Array(await source.arrayBuffer());
      if (b.length < 12) throw new Error("The source image could not be decoded.");
      return { width: 3, height: 2, fromBlob: source.type };
    }
    return { width: source.width, height: source.height, fromImageData: source.data };
  };
  class ImageData { constructor(data, width, height) { Object.assign(this, { data, width, height }); } }
  const opts = { createImageBitmap, ImageData };

  const jpegFrame = { image_info: { width: 3, height: 2, step: 0, encoding: E.compressed }, data: Uint8Array.of(...JPEG, 0xff, 0xd9) };
  assert.equal(isCompressedEncoding(jpegFrame), true);
  const j = await imageToBitmap(jpegFrame, opts);
  assert.deepEqual([j.ok, j.bitmap.fromBlob, j.format.name, j.width], [true, "image/jpeg", "jpeg", 3]);

  const corrupt = await imageToBitmap({ ...jpegFrame, data: JPEG.subarray(0, 6) }, opts);
  assert.deepEqual([corrupt.ok, corrupt.error.code], [false, "decode_failed"]);
  assert.match(corrupt.error.message, /jpeg image could not be decoded/);

  const tiff = await imageToBitmap({ ...jpegFrame, data: Uint8Array.of(0x49, 0x49, 0x2a, 0) }, opts);
  assert.equal(tiff.error.code, "not_drawable");

  const raw = makeImage("bgr888", 2, 1, 3, (dv, o, x) => [x, 20, 30].forEach((b, i) => dv.setUint8(o + i, b)));
  const r = await imageToBitmap(raw, opts);
  assert.equal(r.ok, true);
  assert.equal(r.encoding, "bgr888");
  assert.deepEqual(Array.from(r.bitmap.fromImageData), [30, 20, 0, 255, 30, 20, 1, 255]);
  // the caller says it is an Image though the data looks like a JPEG: decoded as pixels
  assert.equal((await imageToBitmap({ ...raw, data: Uint8Array.of(0xff, 0xd8, 0xff, 1, 2, 3, 4, 5, 6) }, { ...opts, compressed: false })).ok, true);

  const short = await imageToBitmap({ ...raw, data: new Uint8Array(2) }, opts);
  assert.equal(short.error.code, "data_too_short");
  assert.equal(calls.length, 4);  // bad frames never reach the browser's decoder

  if (typeof globalThis.createImageBitmap !== "function") {  // node: no browser to decode with
    assert.equal((await imageToBitmap(raw)).error.code, "no_browser");
  }
});
