// Pixel formats of com.robotraconteur.image.ImageEncoding, by encoding name. Numbers come from the
// device's own definition of the enum (encodingNames(values)); STANDARD_IMAGE_ENCODINGS is the
// standard definition's numbering (stdver 0.10), used when a value comes without definitions.

/** ImageEncoding name → number in the standard definition com.robotraconteur.image (stdver 0.10). */
export const STANDARD_IMAGE_ENCODINGS = Object.freeze({
  unknown: 0,
  rgb888: 0x1000, rgba8888: 0x1001, bgr888: 0x1002, bgra8888: 0x1003, rgba16_16_16_16: 0x1004, bgra16_16_16_16: 0x1005,
  mono8: 0x2000, mono16: 0x2001, mono32: 0x2002, mono_f16: 0x2003, mono_f32: 0x2004, mono_f64: 0x2005,
  bayer_rggb8888: 0x3000, bayer_bggr8888: 0x3001, bayer_gbrg8888: 0x3002, bayer_grbg8888: 0x3003,
  depth_u16: 0x4000, depth_i16: 0x4001, depth_u32: 0x4002, depth_i32: 0x4003, depth_u64: 0x4004, depth_i64: 0x4005,
  depth_f32: 0x4006, depth_f64: 0x4007,
  freeform: 0x5000, compressed: 0x6000, other: 0x8000,
});

/**
 * How each decodable encoding stores a pixel: `kind` ("color", "mono", "bayer", "depth"), `bytes` per
 * pixel, `sample` (the little-endian number type of one sample: u8, u16, u32, u64, i16, i32, i64,
 * f16, f32, f64), for colour the sample index of r, g, b and a (-1: opaque), for bayer the 2×2 pattern.
 */
export const PIXEL_FORMATS = Object.freeze({
  rgb888: { kind: "color", bytes: 3, sample: "u8", r: 0, g: 1, b: 2, a: -1 },
  rgba8888: { kind: "color", bytes: 4, sample: "u8", r: 0, g: 1, b: 2, a: 3 },
  bgr888: { kind: "color", bytes: 3, sample: "u8", r: 2, g: 1, b: 0, a: -1 },
  bgra8888: { kind: "color", bytes: 4, sample: "u8", r: 2, g: 1, b: 0, a: 3 },
  rgba16_16_16_16: { kind: "color", bytes: 8, sample: "u16", r: 0, g: 1, b: 2, a: 3 },
  bgra16_16_16_16: { kind: "color", bytes: 8, sample: "u16", r: 2, g: 1, b: 0, a: 3 },
  mono8: { kind: "mono", bytes: 1, sample: "u8" },
  mono16: { kind: "mono", bytes: 2, sample: "u16" },
  mono32: { kind: "mono", bytes: 4, sample: "u32" },
  mono_f16: { kind: "mono", bytes: 2, sample: "f16" },
  mono_f32: { kind: "mono", bytes: 4, sample: "f32" },
  mono_f64: { kind: "mono", bytes: 8, sample: "f64" },
  bayer_rggb8888: { kind: "bayer", bytes: 1, sample: "u8", pattern: "rggb" },
  bayer_bggr8888: { kind: "bayer", bytes: 1, sample: "u8", pattern: "bggr" },
  bayer_gbrg8888: { kind: "bayer", bytes: 1, sample: "u8", pattern: "gbrg" },
  bayer_grbg8888: { kind: "bayer", bytes: 1, sample: "u8", pattern: "grbg" },
  depth_u16: { kind: "depth", bytes: 2, sample: "u16" },
  depth_i16: { kind: "depth", bytes: 2, sample: "i16" },
  depth_u32: { kind: "depth", bytes: 4, sample: "u32" },
  depth_i32: { kind: "depth", bytes: 4, sample: "i32" },
  depth_u64: { kind: "depth", bytes: 8, sample: "u64" },
  depth_i64: { kind: "depth", bytes: 8, sample: "i64" },
  depth_f32: { kind: "depth", bytes: 4, sample: "f32" },
  depth_f64: { kind: "depth", bytes: 8, sample: "f64" },
});

const STANDARD_BY_NUMBER = new Map(Object.entries(STANDARD_IMAGE_ENCODINGS).map(([name, n]) => [n, name]));

/**
 * number → name of the ImageEncoding enum values `values` ([{name, value}] from the device's
 * definitions); the standard numbering when `values` is absent.
 * @returns {Map<number, string>}
 */
export function encodingNames(values) {
  if (!Array.isArray(values) || !values.length) return STANDARD_BY_NUMBER;
  let names = cache.get(values);
  if (!names) cache.set(values, names = new Map(values.map((v) => [v.value, v.name])));
  return names;
}

const cache = new WeakMap();
