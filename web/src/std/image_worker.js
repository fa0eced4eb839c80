// The Worker that turns standard Image / CompressedImage frames into ImageBitmaps off the page's
// thread (frame_decoder.js starts it as a module Worker). One message in, one out:
//
//   in:  { id, image_info: {width, height, step, encoding}, data: Uint8Array (transferred),
//          compressed: bool, options: {encodings, depthRange, floatRange} }
//   out: { id, result }   result as imageToBitmap gives it; its bitmap transferred
//
// Nothing here throws back at the page: every failure is a result with ok false.

import { imageToBitmap } from "./image_bitmap.js";

self.onmessage = async (ev) => {
  const { id, image_info, data, compressed, options } = ev.data || {};
  let result;
  try {
    result = await imageToBitmap({ image_info, data }, { ...(options || {}), compressed });
  } catch (e) {
    result = { ok: false, error: { code: "decode_failed", message: String(e?.message || e) } };
  }
  if (result.ok) self.postMessage({ id, result }, [result.bitmap]);
  else self.postMessage({ id, result });
};
