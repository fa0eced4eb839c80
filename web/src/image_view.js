// Images inside values, drawn on a canvas: a struct with width, height, (step,) and data (uint8[],
// rows top to bottom, 1, 3 or 4 bytes per pixel: grey, RGB, RGBA), as experimental.createwebcam's
// WebcamImage; or a uint8 multidim array with dims {height, width, channels} (column-major).

/**
 * { width, height, channels, pixel(x, y, c), rows? } when `v` looks like an image, else null; `rows`
 * ({ data, step }) is there for row-major byte images.
 */
export function asImage(v) {
  if (!v || typeof v !== "object") return null;
  if (ArrayBuffer.isView(v.data) && Number(v.width) > 0 && Number(v.height) > 0) {
    const width = Number(v.width), height = Number(v.height);
    const step = Number(v.step) > 0 ? Number(v.step) : v.data.length / height;
    const channels = Math.floor(step / width);
    if (![1, 3, 4].includes(channels) || step * height > v.data.length) return null;
    const data = v.data;
    return { width, height, channels, rows: { data, step }, pixel: (x, y, c) => data[y * step + x * channels + c] };
  }
  if (v.dims && ArrayBuffer.isView(v.array) && v.dims.length >= 2 && v.dims.length <= 3) {
    const [height, width, channels = 1] = Array.from(v.dims, Number);
    if (![1, 3, 4].includes(channels) || height * width * channels !== v.array.length) return null;
    const a = v.array;
    return { width, height, channels, pixel: (x, y, c) => a[y + height * (x + width * c)] };
  }
  return null;
}

/** Draws `image` (from asImage) on `canvas`, resizing the canvas to the image. */
export function drawImage(canvas, image) {
  const { width, height, channels, pixel } = image;
  if (canvas.width !== width) canvas.width = width;
  if (canvas.height !== height) canvas.height = height;
  const ctx = canvas.getContext("2d");
  const out = ctx.createImageData(width, height);
  const px = out.data;
  let o = 0;
  if (image.rows && channels >= 3) {
    // rows of RGB(A) bytes: copy without a call per channel (camera streams are the hot path)
    const { data, step } = image.rows;
    for (let y = 0; y < height; y++) {
      let i = y * step;
      for (let x = 0; x < width; x++, o += 4, i += channels) {
        px[o] = data[i]; px[o + 1] = data[i + 1]; px[o + 2] = data[i + 2];
        px[o + 3] = channels === 4 ? data[i + 3] : 255;
      }
    }
    ctx.putImageData(out, 0, 0);
    return;
  }
  for (let y = 0; y < height; y++) {
    for (let x = 0; x < width; x++, o += 4) {
      if (channels === 1) {
        px[o] = px[o + 1] = px[o + 2] = pixel(x, y, 0);
      } else {
        px[o] = pixel(x, y, 0); px[o + 1] = pixel(x, y, 1); px[o + 2] = pixel(x, y, 2);
      }
      px[o + 3] = channels === 4 ? pixel(x, y, 3) : 255;
    }
  }
  ctx.putImageData(out, 0, 0);
}
