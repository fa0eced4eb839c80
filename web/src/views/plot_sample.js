// What a live plot takes from one value of a wire or pipe: known byte layouts first
// (packet_layouts.js), else the numbers of a value typed by its descriptor (std/plot_fields.js: no
// UUID bytes, identifiers, strings or clock fields; flag words and seqno start hidden), else the
// generic flattening for types the page could not describe; and the value's own time.

import { numericFields } from "../numeric_fields.js";
import { decodeKnown } from "../packet_layouts.js";
import { typedNumericFields, sensorTimestamp } from "../std/plot_fields.js";

/**
 * { pairs: [[name, number, hiddenAtFirst?], ...], t: seconds since the epoch on the sender's clock,
 * or null } of `value` typed by descriptor `d` (or null); `qualifiedType` picks a known layout.
 */
export function plotSample(value, d, qualifiedType = null) {
  const known = decodeKnown(qualifiedType, value);
  if (known) return { pairs: known, t: null };
  if (!d || d.kind === "unknown" || d.kind === "object") return { pairs: numericFields(value, null), t: null };
  let t = null;
  try { t = sensorTimestamp(value, d)?.seconds ?? null; } catch { t = null; }
  return { pairs: typedNumericFields(value, d), t };
}
