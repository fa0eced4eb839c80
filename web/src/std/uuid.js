// com.robotraconteur.uuid.UUID (namedarray, field uint8[16] uuid_bytes) as 8-4-4-4-12 text.

/** The 16 bytes of a UUID value ({uuid_bytes} as the client package gives it, or the bytes), or null. */
export function uuidBytes(v) {
  const bytes = v && !ArrayBuffer.isView(v) && !Array.isArray(v) ? v.uuid_bytes : v;
  if (!bytes || typeof bytes.length !== "number" || bytes.length !== 16) return null;
  for (let i = 0; i < 16; i++) {
    const b = bytes[i];
    if (!Number.isInteger(b) || b < 0 || b > 255) return null;
  }
  return bytes;
}

/** "xxxxxxxx-xxxx-xxxx-xxxx-xxxxxxxxxxxx" (lower case, bytes in order), or null for anything else. */
export function formatUuid(v) {
  const bytes = uuidBytes(v);
  if (!bytes) return null;
  const hex = Array.from(bytes, (b) => b.toString(16).padStart(2, "0")).join("");
  return `${hex.slice(0, 8)}-${hex.slice(8, 12)}-${hex.slice(12, 16)}-${hex.slice(16, 20)}-${hex.slice(20)}`;
}

/** True for the all-zero UUID (RR's "no UUID"). */
export function isNilUuid(v) {
  const bytes = uuidBytes(v);
  return !!bytes && Array.prototype.every.call(bytes, (b) => b === 0);
}

export const renderers = [
  { type: "com.robotraconteur.uuid.UUID", layout: { uuid_bytes: "uint8[16]" }, text: (v) => formatUuid(v) ?? "(not a UUID)" },
];
