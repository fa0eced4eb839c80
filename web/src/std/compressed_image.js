// com.robotraconteur.image.CompressedImage: the format of `data` found by its magic bytes (the
// definition says "Use magic to determine data type"; image_info.encoding is `compressed`, step 0).
// Browsers draw JPEG and PNG (createImageBitmap, see image_bitmap.js); the others are named only.

const ascii = (s) => Array.from(s, (c) => c.charCodeAt(0));

/** Known formats: name, MIME type, whether the dashboard draws it, and its magic bytes. */
export const COMPRESSED_FORMATS = Object.freeze([
  { name: "jpeg", mime: "image/jpeg", drawable: true, magic: [[0, [0xff, 0xd8, 0xff]]] },
  { name: "png", mime: "image/png", drawable: true, magic: [[0, [0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a]]] },
  { name: "gif", mime: "image/gif", drawable: false, magic: [[0, ascii("GIF87a")]], alt: [[[0, ascii("GIF89a")]]] },
  { name: "webp", mime: "image/webp", drawable: false, magic: [[0, ascii("RIFF")], [8, ascii("WEBP")]] },
  { name: "bmp", mime: "image/bmp", drawable: false, magic: [[0, ascii("BM")]] },
  { name: "tiff", mime: "image/tiff", drawable: false, magic: [[0, [0x49, 0x49, 0x2a, 0x00]]], alt: [[[0, [0x4d, 0x4d, 0x00, 0x2a]]]] },
  { name: "jpeg2000", mime: "image/jp2", drawable: false,
    magic: [[0, [0x00, 0x00, 0x00, 0x0c, 0x6a, 0x50, 0x20, 0x20, 0x0d, 0x0a, 0x87, 0x0a]]], alt: [[[0, [0xff, 0x4f, 0xff, 0x51]]]] },
  { name: "jpeg-xl", mime: "image/jxl", drawable: false,
    magic: [[0, [0x00, 0x00, 0x00, 0x0c, 0x4a, 0x58, 0x4c, 0x20, 0x0d, 0x0a, 0x87, 0x0a]]], alt: [[[0, [0xff, 0x0a]]]] },
  { name: "avif", mime: "image/avif", drawable: false, magic: [[4, ascii("ftypavi")]] },
  { name: "heif", mime: "image/heif", drawable: false, magic: [[4, ascii("ftyphei")]], alt: [[[4, ascii("ftypmif1")]]] },
  { name: "qoi", mime: "image/qoi", drawable: false, magic: [[0, ascii("qoif")]] },
  { name: "openexr", mime: "image/x-exr", drawable: false, magic: [[0, [0x76, 0x2f, 0x31, 0x01]]] },
]);

function matches(data, parts) {
  return parts.every(([at, bytes]) => data.length >= at + bytes.length && bytes.every((b, i) => data[at + i] === b));
}

/** The format of compressed image bytes: { name, mime, drawable } or null when no magic matches. */
export function compressedFormat(data) {
  if (!(data instanceof Uint8Array || data instanceof Uint8ClampedArray)) return null;
  for (const f of COMPRESSED_FORMATS) {
    if (matches(data, f.magic) || (f.alt || []).some((parts) => matches(data, parts))) {
      return { name: f.name, mime: f.mime, drawable: f.drawable };
    }
  }
  return null;
}

/**
 * Checks a CompressedImage value: { ok: true, format: {name, mime, drawable}, width, height } (the
 * sizes image_info states; 0 when not given), or { ok: false, error: { code, message } } with code
 * not_an_image, bad_data, empty, unknown_format or not_drawable (named, e.g. "tiff", not drawn).
 */
export function checkCompressedImage(value) {
  if (!value || typeof value !== "object" || !("data" in value)) {
    return { ok: false, error: { code: "not_an_image", message: "not a CompressedImage: data expected" } };
  }
  const data = value.data;
  if (!(data instanceof Uint8Array || data instanceof Uint8ClampedArray)) {
    return { ok: false, error: { code: "bad_data", message: "data must be bytes (uint8[])" } };
  }
  if (!data.length) return { ok: false, error: { code: "empty", message: "the compressed image has no bytes" } };
  const format = compressedFormat(data);
  if (!format) {
    const head = Array.from(data.subarray(0, 4), (b) => b.toString(16).padStart(2, "0")).join(" ");
    return { ok: false, error: { code: "unknown_format", message: `unknown compressed image format (first bytes ${head})` } };
  }
  if (!format.drawable) {
    return { ok: false, format, error: { code: "not_drawable", message: `${format.name} image: not drawn here (JPEG and PNG are)` } };
  }
  const info = value.image_info || {};
  return { ok: true, format, width: Number(info.width) || 0, height: Number(info.height) || 0 };
}
