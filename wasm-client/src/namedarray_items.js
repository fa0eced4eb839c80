// Linked into the Emscripten module with --pre-js (CMakeLists.txt): the items of a namedarray array
// built in JavaScript from their flat typed array, in one call from js_values.cpp. Building each item
// through embind (one call per field) cost about 10 µs a point: a point cloud of 300,000 points took
// 3 s to arrive; in JavaScript it takes a few milliseconds.
//
// rrNamedArrayItems(flat, shape, count, complex) -> Array of `count` plain objects, read in order from
// `flat` (complex element types interleaved real, imag). `shape` is an Array of members, each
// [name, count, array (bool: written [N]), nested shape or null], as NamedArrayShape in C++.
Module["rrNamedArrayItems"] = function (flat, shape, count, complex) {
  let off = 0;
  const leaf = complex
    ? () => { const o = { real: flat[2 * off], imag: flat[2 * off + 1] }; off++; return o; }
    : () => flat[off++];
  const item = (members) => {
    const o = {};
    for (let k = 0; k < members.length; k++) {
      const m = members[k], name = m[0], n = m[1], nested = m[3];
      if (nested) {
        if (!m[2]) { o[name] = item(nested); continue; }
        const arr = new Array(n);
        for (let i = 0; i < n; i++) arr[i] = item(nested);
        o[name] = arr;
      } else if (!m[2]) {
        o[name] = leaf();
      } else if (complex) {
        const arr = new Array(n);
        for (let i = 0; i < n; i++) arr[i] = leaf();
        o[name] = arr;
      } else {
        o[name] = flat.slice(off, off + n);
        off += n;
      }
    }
    return o;
  };
  const items = new Array(count);
  for (let i = 0; i < count; i++) items[i] = item(shape);
  return items;
};
