// Numbers to plot (src/numeric_fields.js, src/packet_layouts.js) and images in values (src/image_view.js).
import { test } from "node:test";
import assert from "node:assert/strict";
import { numericFields } from "../src/numeric_fields.js";
import { asImage } from "../src/image_view.js";

test("struct fields and short vectors flatten to named series", () => {
  const state = { time: 1.5, robot_position: Float64Array.of(100, -200), name: "x", big: new Uint8Array(100) };
  assert.deepEqual(numericFields(state, "experimental.reynard_the_robot.ReynardState"),
    [["time", 1.5], ["robot_position[0]", 100], ["robot_position[1]", -200]]);
  assert.deepEqual(numericFields(7n, null, "DistanceTraveled"), [["DistanceTraveled", 7]]);
});

test("the demo Create's SensorPacket bytes decode", () => {
  const data = new Uint8Array(36);
  const d = new DataView(data.buffer);
  data[0] = 1; data[1] = 2;
  d.setUint16(2, 9, true); d.setInt32(4, -1234, true); d.setInt32(8, 90, true);
  d.setInt32(12, 500, true); d.setInt32(16, -40, true); d.setInt32(20, 18000, true);
  d.setInt16(24, 200, true); d.setInt16(26, 32767, true); d.setUint32(28, 2500, true); d.setUint16(32, 3, true);
  data[34] = 4; data[35] = 60;
  const series = Object.fromEntries(numericFields({ ID: 19, Data: data }, "experimental.create.SensorPacket").map(([n, v]) => [n, v]));
  assert.deepEqual(series, { DistanceTraveled: -1234, AngleTraveled: 90, x: 500, y: -40, heading: 180, velocity: 200,
    radius: 32767, bumpers: 2, wall_hits: 3, seq: 9, time: 2.5, song_length: 4, song_first: 60 });
  // another layout version is not guessed at: generic flattening instead
  data[0] = 2;
  assert.deepEqual(numericFields({ ID: 19, Data: data }, "experimental.create.SensorPacket"), [["ID", 19]]);
});

test("images: WebcamImage structs and [height, width, channel] multidim arrays", () => {
  const data = new Uint8Array(2 * 3 * 3).map((_, i) => i);
  const img = asImage({ width: 3, height: 2, step: 9, data });
  assert.deepEqual([img.width, img.height, img.channels], [3, 2, 3]);
  assert.equal(img.pixel(2, 1, 0), 9 + 6);
  assert.equal(asImage({ width: 3, height: 2, step: 9, data: new Uint8Array(10) }), null);
  // column-major: item (y, x, c) at y + h·(x + w·c)
  const md = { dims: Uint32Array.of(2, 3, 3), array: new Uint8Array(18).map((_, i) => i) };
  const m = asImage(md);
  assert.equal(m.pixel(1, 0, 2), 0 + 2 * (1 + 3 * 2));
  assert.equal(asImage({ dims: Uint32Array.of(2, 3, 2), array: new Uint8Array(12) }), null);
  assert.equal(asImage({ x: 1 }), null);
});
