// Decoding of com.robotraconteur.image.Image values (image_info: width, height, step, encoding;
// data: uint8[], rows top to bottom, `step` bytes apart, samples little-endian) into RGBA bytes shaped
// like ImageData ({width, height, data: Uint8ClampedArray}). Pure and synchronous: it runs in a Worker
// as well as on the page. A frame that cannot be decoded gives an error result, never an exception,
// and is refused from its header alone (no pass over its pixels).
//
// Mapping to 8 bits: 16-bit samples keep their high byte, 32-bit ones their highest byte; floating
// point mono images map [floatRange.min, floatRange.max] (default [0, 1]) to 0..255, clamped, NaN
// black. Depth images are drawn with the colour map of colormap.js over the frame's range of valid
// depths (finite and not 0; others black), reported as `range`; `depthRange` fixes the range instead.
// Bayer mosaics are demosaiced bilinearly (bayer.js).

import { PIXEL_FORMATS, encodingNames } from "./image_encodings.js";
import { halfToNumber } from "./float16.js";
import { jetTable } from "./colormap.js";
import { demosaicBilinear } from "./bayer.js";

function fail(code, message) { return { ok: false, error: { code, message } }; }

/**
 * Checks an Image value's header against its data without reading pixels.
 * @param {{image_info: {width, height, step, encoding}, data: Uint8Array}} value
 * @param {Array<{name: string, value: number}>} [encodings]  the device's ImageEncoding enum values
 * A step equal to the width of a multi-byte encoding, with data of exactly height rows of whole
 * pixels, is read as a step in pixels (what some drivers send) and reported in `note`.
 * @returns {{ok: true, width, height, step, encoding: string, format: object, note?: string} | {ok: false, error: {code, message}}}
 *   error codes: not_an_image, zero_size, unknown_encoding, not_raw (compressed, freeform, other,
 *   unknown: no pixel layout), bad_data (data not bytes), step_too_small, data_too_short
 */
export function checkImage(value, encodings) {
  const info = value?.image_info;
  if (!info || typeof info !== "object" || !("data" in value)) {
    return fail("not_an_image", "not an Image: image_info and data expected");
  }
  const width = Number(info.width), height = Number(info.height), step = Number(info.step);
  if (!Number.isInteger(width) || !Number.isInteger(height) || !Number.isInteger(step) || width < 0 || height < 0 || step < 0) {
    return fail("not_an_image", "image_info width, height and step must be unsigned integers");
  }
  if (width === 0 || height === 0) return fail("zero_size", `the image is ${width}×${height}: nothing to draw`);
  const names = encodingNames(encodings);
  const encoding = typeof info.encoding === "string" ? info.encoding : names.get(Number(info.encoding));
  const format = PIXEL_FORMATS[encoding];
  if (!format) {
    if (encoding === undefined || ![...names.values()].includes(encoding)) {
      return fail("unknown_encoding", `encoding ${info.encoding} is not an ImageEncoding value`);
    }
    return fail("not_raw", `encoding ${encoding} has no pixel layout${encoding === "compressed"
      ? " (a CompressedImage: decoded from its bytes, see compressed_image.js)" : ""}`);
  }
  const data = value.data;
  if (!(data instanceof Uint8Array || data instanceof Uint8ClampedArray)) return fail("bad_data", "data must be bytes (uint8[])");
  const rowBytes = width * format.bytes;
  if (step < rowBytes) {
    // Some drivers write the step in pixels (a FLIR-style mono16 driver sends step = width): when the
    // data holds exactly rows of whole pixels, read them so and say so in `note`.
    if (step === width && format.bytes > 1 && data.length === height * rowBytes) {
      return { ok: true, width, height, step: rowBytes, encoding, format,
        note: `step ${step} read as pixels: rows of ${rowBytes} bytes` };
    }
    return fail("step_too_small", `step ${step} is less than a row of ${width} ${encoding} pixels (${rowBytes} bytes)`);
  }
  if (data.length < height * step) {
    return fail("data_too_short", `data has ${data.length} bytes; ${height} rows of step ${step} need ${height * step}`);
  }
  return { ok: true, width, height, step, encoding, format };
}

/**
 * Decodes an Image value to RGBA.
 * @param {object} value  an Image value as the client package gives it
 * @param {object} [options]
 * @param {Array<{name: string, value: number}>} [options.encodings]  the device's ImageEncoding enum
 *   values (descriptor enumValues); the standard numbering without them
 * @param {Uint8ClampedArray} [options.out]  a buffer to reuse when it has width·height·4 bytes
 * @param {{min: number, max: number}} [options.depthRange]  a fixed range for depth images
 * @param {{min: number, max: number}} [options.floatRange]  the range of mono_f16/f32/f64 (default 0..1)
 * @returns {{ok: true, width, height, data: Uint8ClampedArray, encoding: string, range?: {min, max}|null,
 *   note?: string} | {ok: false, error: {code, message}}}  (codes of checkImage)
 */
export function decodeImage(value, options = {}) {
  const head = checkImage(value, options.encodings);
  if (!head.ok) return head;
  const { width, height, step, encoding, format } = head;
  const size = width * height * 4;
  const out = options.out instanceof Uint8ClampedArray && options.out.length === size ? options.out : new Uint8ClampedArray(size);
  const data = value.data;
  const result = { ok: true, width, height, data: out, encoding };
  if (head.note) result.note = head.note;
  if (format.kind === "color") decodeColor(data, width, height, step, format, out);
  else if (format.kind === "mono") decodeMono(data, width, height, step, format, out, options.floatRange);
  else if (format.kind === "bayer") demosaicBilinear(data, width, height, step, format.pattern, out);
  else result.range = decodeDepth(data, width, height, step, format, out, options.depthRange);
  return result;
}

/** A reader of one little-endian sample of type `sample` at a byte offset of `data`. */
function sampleReader(sample, data) {
  const dv = new DataView(data.buffer, data.byteOffset, data.byteLength);
  switch (sample) {
    case "u8": return (i) => data[i];
    case "u16": return (i) => data[i] | (data[i + 1] << 8);
    case "i16": return (i) => dv.getInt16(i, true);
    case "u32": return (i) => dv.getUint32(i, true);
    case "i32": return (i) => dv.getInt32(i, true);
    case "u64": return (i) => dv.getUint32(i + 4, true) * 4294967296 + dv.getUint32(i, true);
    case "i64": return (i) => dv.getInt32(i + 4, true) * 4294967296 + dv.getUint32(i, true);
    case "f16": return (i) => halfToNumber(data[i] | (data[i + 1] << 8));
    case "f32": return (i) => dv.getFloat32(i, true);
    case "f64": return (i) => dv.getFloat64(i, true);
    default: throw new Error(`no reader for ${sample}`);
  }
}

function decodeColor(data, width, height, step, f, out) {
  // 8-bit samples as they are; 16-bit ones by their high (second, little-endian) byte
  const size = f.sample === "u8" ? 1 : 2, hi = size - 1;
  const r = f.r * size + hi, g = f.g * size + hi, b = f.b * size + hi, a = f.a * size + hi;
  let o = 0;
  for (let y = 0; y < height; y++) {
    let i = y * step;
    for (let x = 0; x < width; x++, i += f.bytes, o += 4) {
      out[o] = data[i + r]; out[o + 1] = data[i + g]; out[o + 2] = data[i + b];
      out[o + 3] = f.a < 0 ? 255 : data[i + a];
    }
  }
}

function decodeMono(data, width, height, step, f, out, floatRange) {
  let toByte;
  if (f.sample === "u8" || f.sample === "u16" || f.sample === "u32") {
    const hi = f.bytes - 1;  // the highest byte of the sample
    toByte = (i) => data[i + hi];
  } else {
    const read = sampleReader(f.sample, data);
    const lo = floatRange ? Number(floatRange.min) : 0, span = floatRange ? Number(floatRange.max) - lo : 1;
    toByte = (i) => {
      const v = (read(i) - lo) / span;
      return v > 0 ? (v < 1 ? Math.round(v * 255) : 255) : 0;  // NaN and below the range: 0
    };
  }
  let o = 0;
  for (let y = 0; y < height; y++) {
    let i = y * step;
    for (let x = 0; x < width; x++, i += f.bytes, o += 4) {
      out[o] = out[o + 1] = out[o + 2] = toByte(i);
      out[o + 3] = 255;
    }
  }
}

function decodeDepth(data, width, height, step, f, out, fixed) {
  const read = sampleReader(f.sample, data);
  let min = Infinity, max = -Infinity;
  if (fixed) {
    min = Number(fixed.min); max = Number(fixed.max);
  } else {
    for (let y = 0; y < height; y++) {
      let i = y * step;
      for (let x = 0; x < width; x++, i += f.bytes) {
        const v = read(i);
        if (v !== 0 && Number.isFinite(v)) {
          if (v < min) min = v;
          if (v > max) max = v;
        }
      }
    }
  }
  const valid = min <= max;
  const scale = valid && max > min ? 255 / (max - min) : 0;
  const lut = jetTable();
  let o = 0;
  for (let y = 0; y < height; y++) {
    let i = y * step;
    for (let x = 0; x < width; x++, i += f.bytes, o += 4) {
      const v = read(i);
      if (valid && v !== 0 && Number.isFinite(v)) {
        const k = 3 * (v <= min ? 0 : v >= max ? 255 : Math.round((v - min) * scale));
        out[o] = lut[k]; out[o + 1] = lut[k + 1]; out[o + 2] = lut[k + 2];
      } else {
        out[o] = out[o + 1] = out[o + 2] = 0;
      }
      out[o + 3] = 255;
    }
  }
  return valid ? { min, max } : null;
}
