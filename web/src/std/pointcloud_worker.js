// The Worker that colours point clouds off the page's thread (pointcloud_decoder.js starts it as a
// module Worker). One message in, one out:
//
//   in:  { id, packed: { count, positions, intensity, rgb } (packCloud's arrays, transferred), options }
//   out: { id, result }   result: colorCloud's drawable cloud with ok true and `ms` (the time it took),
//        its arrays transferred; or { ok: false, error } (never a throw back at the page)

import { colorCloud } from "./pointcloud.js";

self.onmessage = (ev) => {
  const { id, packed, options } = ev.data || {};
  let result;
  try {
    const t0 = performance.now();
    result = { ok: true, ...colorCloud(packed, options || {}) };
    result.ms = performance.now() - t0;
  } catch (e) {
    self.postMessage({ id, result: { ok: false, error: { code: "decode_failed", message: String(e?.message || e) } } });
    return;
  }
  self.postMessage({ id, result }, [result.positions.buffer, result.colors.buffer]);
};
