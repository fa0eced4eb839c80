// The resource panel's pure logic (panels/resource_panel.js): com.robotraconteur.resource parts put
// together into one resource's bytes, bounded.

/** Bytes of one resource the page downloads at most. */
export const MAX_RESOURCE_BYTES = 64 * 1024 * 1024;

/**
 * Collects ResourceParts (each { info, data_offset, data }) into one Uint8Array of the info's total_size.
 * Throws Error for a part outside the total, a total above `max`, or bytes missing at the end.
 */
export function assembleParts(parts, max = MAX_RESOURCE_BYTES) {
  if (!parts.length) return new Uint8Array(0);
  const total = Number(parts[0]?.info?.total_size ?? parts.reduce((n, p) => n + (p.data?.length ?? 0), 0));
  if (!Number.isSafeInteger(total) || total < 0) throw new Error("the resource's total_size is not a size");
  if (total > max) throw new Error(`the resource is ${total} bytes, more than the ${max} the page downloads`);
  const out = new Uint8Array(total);
  let filled = 0;
  for (const p of parts) {
    const offset = Number(p.data_offset ?? 0), data = p.data ?? new Uint8Array(0);
    if (!Number.isSafeInteger(offset) || offset < 0 || offset + data.length > total) throw new Error(`a part at ${p.data_offset} of ${data.length} bytes is outside the resource's ${total}`);
    out.set(data, offset);
    filled += data.length;
  }
  if (filled < total) throw new Error(`${total - filled} of the resource's ${total} bytes did not come`);
  return out;
}

/** "12.5 KiB": a byte count as short text. */
export function sizeText(n) {
  const v = Number(n);
  if (!Number.isFinite(v)) return "";
  if (v < 1024) return `${v} B`;
  if (v < 1024 * 1024) return `${(v / 1024).toFixed(1)} KiB`;
  return `${(v / 1024 / 1024).toFixed(1)} MiB`;
}
