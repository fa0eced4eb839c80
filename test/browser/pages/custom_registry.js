// A page of its own on the dashboard (custom_registry.test.mjs): the standard panels, the standard
// renderers plus two for the demo webcam's types (experimental.createwebcam), registered the way
// docs/dashboard.md "A page of your own" describes.
//   WebcamImage_size  a custom type: its own one-line text
//   WebcamImage       a custom picture format: its own text and an `image` hook (RGB bytes to RGBA
//                     pixels, red and blue swapped so that a test can tell this hook drew the picture)

import { startDashboard } from "../src/dashboard.js";
import { standardRegistry } from "../src/std/standard.js";

const W = "experimental.createwebcam";
const size = { width: "int32", height: "int32", step: "int32" };

function webcamPixels(v) {
  const { width, height, step, data } = v;
  if (!(width > 0 && height > 0 && step >= width * 3 && data?.length >= step * height)) {
    return { ok: false, error: { code: "short_data", message: `${width}×${height} needs ${step * height} bytes` } };
  }
  const out = new Uint8ClampedArray(width * height * 4);
  for (let y = 0; y < height; y++) {
    for (let x = 0; x < width; x++) {
      const i = y * step + x * 3, o = (y * width + x) * 4;
      out[o] = data[i + 2];
      out[o + 1] = data[i + 1];
      out[o + 2] = data[i];
      out[o + 3] = 255;
    }
  }
  return { ok: true, width, height, data: out };
}

const renderers = standardRegistry().register(
  { type: `${W}.WebcamImage_size`, layout: size, text: (v) => `custom size ${v.width} by ${v.height}` },
  { type: `${W}.WebcamImage`, layout: { ...size, data: "uint8[]" }, text: (v) => `custom picture ${v.width} by ${v.height}`, image: webcamPixels },
);

startDashboard({ renderers });
