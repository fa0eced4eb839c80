// The colour map of depth images: "jet" (dark blue, blue, cyan, yellow, red, dark red), as a table
// of 256 RGB entries, linear between the stops below. Index 0 is the nearest depth of the frame's
// range, 255 the farthest.

/** [index, r, g, b] stops of the map. */
export const JET_STOPS = Object.freeze([
  [0, 0, 0, 143], [32, 0, 0, 255], [96, 0, 255, 255], [160, 255, 255, 0], [224, 255, 0, 0], [255, 128, 0, 0],
]);

let table = null;

/** The map as 256 × [r, g, b] bytes (Uint8Array of 768), made once. */
export function jetTable() {
  if (table) return table;
  table = new Uint8Array(256 * 3);
  for (let s = 0; s + 1 < JET_STOPS.length; s++) {
    const [i0, ...c0] = JET_STOPS[s];
    const [i1, ...c1] = JET_STOPS[s + 1];
    for (let i = i0; i <= i1; i++) {
      const f = (i - i0) / (i1 - i0);
      for (let c = 0; c < 3; c++) table[i * 3 + c] = Math.round(c0[c] + (c1[c] - c0[c]) * f);
    }
  }
  return table;
}
