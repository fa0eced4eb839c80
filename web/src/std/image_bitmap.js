// A standard Image or CompressedImage value (com.robotraconteur.image) to an ImageBitmap, for the
// dashboard and for pages that use the client package directly; and any value through its renderer's
// picture hooks (pictureToBitmap: the standard images are two such renderers):
//
//   import { imageToBitmap } from "./std/image_bitmap.js";
//   const frame = await endpoint.receive();                  // e.g. a Camera's frame_stream packet
//   const r = await imageToBitmap(frame, { compressed: false });
//   if (r.ok) canvas.getContext("2d").drawImage(r.bitmap, 0, 0); else console.warn(r.error.message);
//
// Works on the page and in a Worker (both have createImageBitmap). Never rejects: a frame that
// cannot be drawn resolves to { ok: false, error: { code, message } }.

import { encodingNames } from "./image_encodings.js";
import { standardPictureRenderer } from "./image_renderers.js";

/**
 * @param {object} value  an Image or CompressedImage value ({image_info, data}) as the client package gives it
 * @param {object} [options]
 * @param {boolean} [options.compressed]  true for a CompressedImage, false for an Image; when not
 *   given, image_info.encoding `compressed` tells (Image and CompressedImage have the same fields)
 * @param {Array<{name: string, value: number}>} [options.encodings]  the device's ImageEncoding values
 * @param {object} [options.depthRange] [options.floatRange] [options.out]  as decodeImage (image_decode.js)
 * @param {Function} [options.createImageBitmap]  defaults to the global one
 * @param {Function} [options.ImageData]  defaults to the global one
 * @returns {Promise<{ok: true, bitmap: ImageBitmap, width: number, height: number, encoding?: string,
 *   format?: object, range?: object, note?: string} | {ok: false, error: {code: string, message: string}}>}
 *   error codes: those of checkImage (image_decode.js) and checkCompressedImage (compressed_image.js),
 *   decode_failed (the browser could not decode the compressed bytes, e.g. a corrupt JPEG),
 *   no_browser (no createImageBitmap here)
 */
export function imageToBitmap(value, options = {}) {
  const compressed = options.compressed ?? isCompressedEncoding(value, options.encodings);
  return pictureToBitmap(value, standardPictureRenderer(compressed), options, options);
}

/**
 * A value to an ImageBitmap through its renderer's picture hooks (registry.js "Renderer"): a renderer
 * with `compressed` gives the format of bytes the browser decodes (the hook's `bytes`, else the value's
 * `data`), one with `image` gives RGBA pixels. Resolves like imageToBitmap; never rejects.
 * @param {any} value  as the client package gives it
 * @param {object} renderer  the value's renderer (its `image` or `compressed` hook)
 * @param {object} [ctx]  the renderer context (encodings, clockEnum, outline, depthRange, ...)
 * @param {{createImageBitmap?: Function, ImageData?: Function}} [env]  stand-ins for the browser's
 */
export async function pictureToBitmap(value, renderer, ctx = {}, env = {}) {
  const create = env.createImageBitmap || globalThis.createImageBitmap;
  const ImageDataCtor = env.ImageData || globalThis.ImageData;
  if (typeof create !== "function") return fail("no_browser", "createImageBitmap is not available here");
  if (renderer?.compressed) {
    let c;
    try { c = renderer.compressed(value, ctx); } catch (e) { c = failed("not_an_image", e); }
    if (!c?.ok) return { ok: false, error: c?.error ?? { code: "not_an_image", message: "not a compressed picture" } };
    try {
      const bitmap = await create(new Blob([c.bytes ?? value.data], { type: c.format.mime }));
      return { ok: true, bitmap, width: bitmap.width, height: bitmap.height, format: c.format };
    } catch (e) {
      return fail("decode_failed", `the ${c.format.name} image could not be decoded: ${e?.message || e}`);
    }
  }
  if (typeof renderer?.image !== "function") return fail("no_picture", `${renderer?.type ?? "this type"} has no picture hook`);
  let d;
  try { d = await renderer.image(value, ctx); } catch (e) { d = failed("decode_failed", e); }
  if (!d?.ok) return { ok: false, error: d?.error ?? { code: "decode_failed", message: "no picture" } };
  if (typeof ImageDataCtor !== "function") return fail("no_browser", "ImageData is not available here");
  try {
    const bitmap = await create(new ImageDataCtor(d.data, d.width, d.height));
    const out = { ok: true, bitmap, width: d.width, height: d.height };
    if (d.encoding !== undefined) out.encoding = d.encoding;
    if (d.range !== undefined) out.range = d.range;
    if (d.note) out.note = d.note;
    return out;
  } catch (e) {
    return fail("decode_failed", `the image could not be made a bitmap: ${e?.message || e}`);
  }
}

/** True when the value's image_info.encoding is `compressed` (by the device's enum, or the standard one). */
export function isCompressedEncoding(value, encodings) {
  const e = value?.image_info?.encoding;
  return e === "compressed" || encodingNames(encodings).get(Number(e)) === "compressed";
}

function fail(code, message) { return { ok: false, error: { code, message } }; }
function failed(code, e) { return { ok: false, error: { code, message: String(e?.message || e) } }; }
