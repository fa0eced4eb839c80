// Shared by the standard-type browser tests (std_camera, std_images, std_robot): the Python devices
// of test/browser/devices, screenshots (also for docs/img with RR_DOCS_SCREENSHOTS=1), the pixels
// of a canvas, and the synthetic camera's frame pattern.

import fs from "node:fs";
import path from "node:path";
import { ROOT, settings, startProcess } from "./harness.mjs";

export const DEVICES = path.join(ROOT, "test/browser/devices");

/** Starts test/browser/devices/<script> with the venv's Python; resolves { child, info } (its ready line). */
export function startDevice(script, args = [], options = {}) {
  const s = settings();
  return startProcess(script, s.python, ["-u", path.join(DEVICES, script), ...args], "url", 90000, options);
}

/**
 * A screenshot of `target` (a page or locator) to $RR_ARTIFACTS/<name>; with RR_DOCS_SCREENSHOTS=1
 * also to docs/img/<name> (the pictures of docs/dashboard.md), unless `docs` is false.
 */
export async function screenshot(target, name, { docs = true, ...options } = {}) {
  const s = settings();
  fs.mkdirSync(s.artifacts, { recursive: true });
  const forDocs = docs && process.env.RR_DOCS_SCREENSHOTS === "1";
  try {
    await target.screenshot({ path: path.join(s.artifacts, name), ...options });
  } catch (e) {
    // Outside a docs run the picture is only an artifact, not a check: a page starved of frames under
    // load (Playwright waits for the element to be stable) must not fail the test it illustrates.
    if (forDocs) throw e;
    console.log(`# screenshot ${name} not taken: ${e.message.split("\n")[0]}`);
    return;
  }
  if (forDocs) {
    fs.mkdirSync(path.join(ROOT, "docs/img"), { recursive: true });
    fs.copyFileSync(path.join(s.artifacts, name), path.join(ROOT, "docs/img", name));
  }
}

/** { width, height, data: number[] (RGBA) } of the backing pixels of a canvas locator. */
export function canvasPixels(locator) {
  return locator.evaluate((canvas) => {
    const g = canvas.getContext("2d", { willReadFrequently: true });
    return { width: canvas.width, height: canvas.height, data: Array.from(g.getImageData(0, 0, canvas.width, canvas.height).data) };
  });
}

/** Largest and mean per-channel difference (RGB and alpha) between two RGBA byte arrays, and how many exceed `tolerance`. */
export function pixelDiff(actual, expected, tolerance = 0) {
  let max = 0, sum = 0, over = 0;
  for (let i = 0; i < expected.length; i++) {
    const d = Math.abs(actual[i] - expected[i]);
    if (d > max) max = d;
    if (d > tolerance) over++;
    sum += d;
  }
  return { max, mean: sum / expected.length, over, length: actual.length === expected.length };
}

/**
 * In the page: the synthetic camera's frame number (k mod 2^columns, from the top row of blocks) on a
 * canvas and the difference of every block from the frame that number stands for
 * (test/browser/devices/camera_synthetic.py). `margin` pixels of each block's border are left out
 * (JPEG's colour blocks bleed there). Returns { k, max, mean, width, height }.
 */
export function compareWithPattern(canvasLocator, pattern, margin = 0) {
  return canvasLocator.evaluate((canvas, { block, palette, mono, margin }) => {
    const { width, height } = canvas;
    const px = canvas.getContext("2d", { willReadFrequently: true }).getImageData(0, 0, width, height).data;
    const cols = Math.ceil(width / block), rows = Math.ceil(height / block);
    const at = (x, y) => { const o = (y * width + x) * 4; return [px[o], px[o + 1], px[o + 2]]; };
    let k = 0;
    for (let bx = 0; bx < cols; bx++) {
      const [r, g, b] = at(Math.min(width - 1, bx * block + (block >> 1)), Math.min(height - 1, block >> 1));
      if (r + g + b > 3 * 128) k |= 1 << bx;
    }
    let max = 0, sum = 0, n = 0;
    for (let by = 0; by < rows; by++) {
      for (let bx = 0; bx < cols; bx++) {
        let want;
        if (by === 0) want = (k >> bx) & 1 ? [255, 255, 255] : [0, 0, 0];
        else {
          const i = (bx + 3 * by + k) % 8;
          want = mono ? [32 * i + 16, 32 * i + 16, 32 * i + 16] : palette[i];
        }
        for (let y = by * block + margin; y < Math.min(height, (by + 1) * block) - margin; y++) {
          for (let x = bx * block + margin; x < Math.min(width, (bx + 1) * block) - margin; x++) {
            const got = at(x, y);
            for (let c = 0; c < 3; c++) {
              const d = Math.abs(got[c] - want[c]);
              if (d > max) max = d;
              sum += d;
              n++;
            }
          }
        }
      }
    }
    return { k, max, mean: sum / n, width, height };
  }, { block: pattern.block, palette: pattern.palette, mono: !!pattern.mono, margin });
}
