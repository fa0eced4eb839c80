// The light panel's pure parts (src/lighting/light_state.js): ColorRGBA to and from "#rrggbb", brightness
// in %, and the swatch's colour (black when off, the colour scaled by the intensity).
import { test } from "node:test";
import assert from "node:assert/strict";
import { rgba, colorHex, hexColor, percentText, glowColor } from "../src/lighting/light_state.js";

test("colours: object or four numbers; hex both ways; alpha kept", () => {
  assert.deepEqual(rgba({ r: 1, g: 0.75, b: 0.3, a: 1 }), { r: 1, g: 0.75, b: 0.3, a: 1 });
  assert.deepEqual(rgba(Float64Array.from([0, 0.5, 1, 0.5])), { r: 0, g: 0.5, b: 1, a: 0.5 });
  assert.equal(rgba([1, 2]), null);
  assert.equal(rgba({ r: "x", g: 0, b: 0, a: 0 }), null);
  assert.equal(colorHex({ r: 1, g: 0.75, b: 0.3, a: 1 }), "#ffbf4d");
  assert.equal(colorHex({ r: 2, g: -1, b: 0, a: 1 }), "#ff0000");  // clamped
  assert.deepEqual(hexColor("#3366CC", 0.5), { r: 0.2, g: 0.4, b: 0.8, a: 0.5 });
  assert.equal(hexColor("red"), null);
});

test("brightness in % and the swatch's colour", () => {
  assert.equal(percentText(0.5), "50%");
  assert.equal(percentText(0.123), "12.3%");
  assert.equal(percentText(undefined), "");
  assert.equal(glowColor({ on: false, intensity: 1, color: { r: 1, g: 1, b: 1, a: 1 } }), "rgb(0, 0, 0)");
  assert.equal(glowColor({ on: true }), "rgb(255, 255, 255)");
  assert.equal(glowColor({ on: true, intensity: 0.5 }), "rgb(128, 128, 128)");
  assert.equal(glowColor({ on: true, intensity: 0.8, color: { r: 0.2, g: 0.4, b: 0.8, a: 1 } }), "rgb(41, 82, 163)");
});
