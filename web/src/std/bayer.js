// Demosaicing of 8-bit Bayer images (bayer_rggb8888, bayer_bggr8888, bayer_gbrg8888, bayer_grbg8888)
// by bilinear interpolation: each pixel keeps its own colour, and each missing colour is the mean of
// the pixels of that colour among its 8 neighbours (4 in a cross or on the diagonals, or the 2 beside
// it; fewer on the border), rounded to the nearest integer (halves up).

const CHANNEL = { r: 0, g: 1, b: 2 };

/**
 * Writes RGBA bytes of a `width`×`height` mosaic into `out` (Uint8ClampedArray of width·height·4).
 * @param {Uint8Array} data  rows of one byte per pixel, `step` bytes apart
 * @param {string} pattern  colours of the top-left 2×2 block, row by row: "rggb", "bggr", "gbrg", "grbg"
 */
export function demosaicBilinear(data, width, height, step, pattern, out) {
  const colour = Uint8Array.from(pattern, (c) => CHANNEL[c]);
  const sums = new Float64Array(3);
  const counts = new Uint8Array(3);
  let o = 0;
  for (let y = 0; y < height; y++) {
    const yFirst = y > 0 ? y - 1 : 0, yLast = y + 1 < height ? y + 1 : y;
    for (let x = 0; x < width; x++, o += 4) {
      const xFirst = x > 0 ? x - 1 : 0, xLast = x + 1 < width ? x + 1 : x;
      sums[0] = sums[1] = sums[2] = 0;
      counts[0] = counts[1] = counts[2] = 0;
      for (let yy = yFirst; yy <= yLast; yy++) {
        const row = yy * step, rowColour = (yy & 1) * 2;
        for (let xx = xFirst; xx <= xLast; xx++) {
          const c = colour[rowColour + (xx & 1)];
          sums[c] += data[row + xx];
          counts[c]++;
        }
      }
      const own = colour[(y & 1) * 2 + (x & 1)];
      for (let c = 0; c < 3; c++) {
        out[o + c] = c === own ? data[y * step + x] : counts[c] ? Math.round(sums[c] / counts[c]) : 0;
      }
      out[o + 3] = 255;
    }
  }
}
