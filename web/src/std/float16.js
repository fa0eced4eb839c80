// IEEE 754 half precision (binary16) to a JS number, for mono_f16 images (no Float16Array in every
// browser yet).

/** The number that the 16 bits `h` (an integer 0..65535) encode: ±0, subnormals, ±Infinity, NaN. */
export function halfToNumber(h) {
  const sign = h & 0x8000 ? -1 : 1;
  const exp = (h >> 10) & 0x1f;
  const frac = h & 0x3ff;
  if (exp === 0) return sign * frac * 2 ** -24;
  if (exp === 31) return frac ? NaN : sign * Infinity;
  return sign * (1 + frac / 1024) * 2 ** (exp - 15);
}
