// The light panel's pure logic (panels/light_panel.js): com.robotraconteur.lighting values as an
// operator reads and sets them. Intensity is 0 to 1 (shown in %); ColorRGBA fields are 0 to 1.

import { namedFields } from "../std/geometry.js";

const RGBA = ["r", "g", "b", "a"];
const byte = (x) => Math.round(Math.min(1, Math.max(0, Number(x))) * 255);

/** {r, g, b, a} of a ColorRGBA value (object or 4 numbers), or null. */
export function rgba(v) {
  const c = namedFields(v, RGBA);
  return c && RGBA.every((k) => Number.isFinite(c[k])) ? { r: c.r, g: c.g, b: c.b, a: c.a } : null;
}

/** "#ffbf4d" of a ColorRGBA (alpha left out), or null. */
export function colorHex(v) {
  const c = rgba(v);
  return c ? `#${[c.r, c.g, c.b].map((x) => byte(x).toString(16).padStart(2, "0")).join("")}` : null;
}

/** The ColorRGBA {r, g, b, a} of "#rrggbb" with alpha `a` (default 1); null for other text. */
export function hexColor(hex, a = 1) {
  const m = /^#([0-9a-f]{2})([0-9a-f]{2})([0-9a-f]{2})$/i.exec(String(hex));
  if (!m) return null;
  const [r, g, b] = m.slice(1).map((x) => Number(`0x${x}`) / 255);
  return { r, g, b, a };
}

/** "40%" of an intensity 0..1; "" for no number. */
export function percentText(x) {
  const v = Number(x);
  return Number.isFinite(v) ? `${Math.round(v * 1000) / 10}%` : "";
}

/**
 * The CSS colour of what the light gives: black when off, else its colour (white without one) scaled by
 * its intensity (1 without one), as "rgb(r, g, b)".
 */
export function glowColor({ on, intensity, color }) {
  if (!on) return "rgb(0, 0, 0)";
  const c = rgba(color) ?? { r: 1, g: 1, b: 1 };
  const k = Number.isFinite(Number(intensity)) && intensity !== undefined && intensity !== null ? Math.min(1, Math.max(0, Number(intensity))) : 1;
  return `rgb(${byte(c.r * k)}, ${byte(c.g * k)}, ${byte(c.b * k)})`;
}
