// The point cloud modules without a browser: points copied out of the client package's objects, holes
// dropped, the colour modes (the packed rgb's bits, intensity and height through the jet map), parts put
// back into whole clouds, the newest cloud winning in CloudDecoder, the text, and the renderers' layouts
// against the standard definitions read at test time (an older layout falling back).
import { test } from "node:test";
import assert from "node:assert/strict";
import { packCloud, colorCloud, colorModeFor, unpackRgb, CloudAssembler, boundsText, cloudText, CLOUD_TYPES, CLOUD_PART_TYPES } from "../src/std/pointcloud.js";
import { CloudDecoder } from "../src/std/pointcloud_decoder.js";
import { jetTable } from "../src/std/colormap.js";
import { RobdefOutline } from "../src/std/robdef_outline.js";
import { standardDescriber } from "../src/std/standard.js";
import { standardDefinitions, SKIP_REASON } from "./std_fixtures.mjs";

const defs = standardDefinitions();
/** The packed colour float of 0x00RRGGBB, as PCL and the tests' device pack it. */
const packed = (rgb) => new Float32Array(new Uint32Array([rgb]).buffer)[0];
const jet = (t) => { const j = jetTable(), i = Math.round(t * 255) * 3; return [j[i], j[i + 1], j[i + 2]]; };

test("packCloud: Points and PointCloud2Points into flat arrays", () => {
  const p1 = packCloud({ points: [{ x: 1, y: 2, z: 3 }, { x: -1, y: 0.5, z: 0 }] });
  assert.equal(p1.count, 2);
  assert.deepEqual(Array.from(p1.positions), [1, 2, 3, -1, 0.5, 0]);
  assert.equal(p1.intensity, null);
  assert.equal(p1.rgb, null);
  const p2 = packCloud({ points: [
    { point: { x: 0, y: 0, z: 1 }, intensity: 40, normal: { x: 0, y: 0, z: 1 }, rgb: { rgb: packed(0xe62828) }, moment_invariants: new Float32Array(3), channel: 0 },
  ] });
  assert.deepEqual(Array.from(p2.positions), [0, 0, 1]);
  assert.deepEqual(Array.from(p2.intensity), [40]);
  assert.deepEqual(unpackRgb(p2.rgb[0]), [0xe6, 0x28, 0x28]);
  assert.equal(packCloud({ points: null }).count, 0);
  assert.equal(packCloud(null).count, 0);
});

test("colorCloud: holes dropped, bounds, colour by rgb, intensity or height", () => {
  const cloud = { points: [
    { point: { x: 0, y: 0, z: 0 }, intensity: 10, rgb: { rgb: packed(0x102030) } },
    { point: { x: NaN, y: 0, z: 0 }, intensity: 99, rgb: { rgb: packed(0xffffff) } },
    { point: { x: 2, y: -1, z: 4 }, intensity: 30, rgb: { rgb: packed(0xe62828) } },
    { point: { x: 1, y: 1, z: 2 }, intensity: 20, rgb: { rgb: packed(0x00ff00) } },
  ] };
  const p = packCloud(cloud);
  assert.equal(colorModeFor(p), "rgb");
  const rgb = colorCloud(p);
  assert.equal(rgb.count, 3);
  assert.equal(rgb.mode, "rgb");
  assert.deepEqual(Array.from(rgb.positions), [0, 0, 0, 2, -1, 4, 1, 1, 2]);
  assert.deepEqual(Array.from(rgb.colors), [0x10, 0x20, 0x30, 0xe6, 0x28, 0x28, 0, 255, 0]);
  assert.deepEqual(rgb.min, [0, -1, 0]);
  assert.deepEqual(rgb.max, [2, 1, 4]);
  assert.equal(rgb.range, null);
  const byIntensity = colorCloud(p, { mode: "intensity" });
  assert.deepEqual(byIntensity.range, [10, 30]);   // the hole's 99 is not in it
  assert.deepEqual(Array.from(byIntensity.colors), [...jet(0), ...jet(1), ...jet(0.5)]);
  const byHeight = colorCloud(p, { mode: "height" });
  assert.deepEqual(byHeight.range, [0, 4]);
  assert.deepEqual(Array.from(byHeight.colors), [...jet(0), ...jet(1), ...jet(0.5)]);
  // a fixed range clamps
  assert.deepEqual(Array.from(colorCloud(p, { mode: "height", range: [0, 2] }).colors.slice(3, 6)), jet(1));
  // positions only: height; a mode the cloud lacks falls back
  const plain = packCloud({ points: [{ x: 0, y: 0, z: 1 }] });
  assert.equal(colorModeFor(plain, "rgb"), "height");
  assert.equal(colorModeFor(plain, "intensity"), "height");
  const none = colorCloud(packCloud({ points: [{ x: NaN, y: 0, z: 0 }] }));
  assert.equal(none.count, 0);
  assert.equal(none.min, null);
});

test("CloudAssembler: parts in order make the whole cloud; gaps and restarts drop it", () => {
  const part = (offset, total, xs) => ({ points_offset: offset, points_total_len: total, points: xs.map((x) => ({ x, y: 0, z: 0 })) });
  const a = new CloudAssembler();
  assert.equal(a.push(part(0, 5, [0, 1])), null);
  assert.equal(a.push(part(2, 5, [2, 3])), null);
  const whole = a.push(part(4, 5, [4]));
  assert.equal(whole.count, 5);
  assert.deepEqual(Array.from(whole.positions).filter((_, i) => i % 3 === 0), [0, 1, 2, 3, 4]);
  // joined mid-cloud: stray parts until the next offset 0
  const b = new CloudAssembler();
  assert.equal(b.push(part(2, 4, [2, 3])), null);
  assert.equal(b.stray, 1);
  // a gap drops the cloud begun
  assert.equal(b.push(part(0, 4, [0, 1])), null);
  assert.equal(b.push(part(3, 4, [3])), null);
  assert.equal(b.dropped, 1);
  // a new cloud before the last was whole drops it
  b.push(part(0, 4, [0, 1]));
  b.push(part(0, 4, [0, 1]));
  assert.equal(b.dropped, 2);
  assert.equal(b.push(part(2, 4, [2, 3])).count, 4);
  // bad sizes refused
  const c = new CloudAssembler(10);
  assert.equal(c.push(part(0, 11, [0])), null);
  assert.equal(c.push(part(0, 2, [0, 1, 2])), null);
  assert.equal(c.push({ points_offset: "x", points_total_len: 2, points: [] }), null);
});

test("CloudDecoder: one cloud colouring, one waiting, the rest dropped for newer", async () => {
  const results = [];
  const dec = new CloudDecoder({ Worker: null, onResult: (r, meta) => results.push([r.count, meta.n]) });
  const cloud = (n) => ({ points: Array.from({ length: n }, (_, i) => ({ x: i, y: 0, z: 0 })) });
  for (let n = 1; n <= 5; n++) dec.submit({ cloud: cloud(n) }, {}, { n });
  await new Promise((r) => setTimeout(r, 20));
  // the first started at once, 5 took the waiting place of 2, 3 and 4
  assert.deepEqual(results, [[1, 1], [5, 5]]);
  assert.equal(dec.stats.dropped, 3);
  assert.equal(dec.stats.decoded, 2);
  assert.ok(!dec.inWorker);
  dec.dispose();
  dec.submit({ cloud: cloud(1) });
  await new Promise((r) => setTimeout(r, 10));
  assert.equal(results.length, 2, "nothing after dispose");
});

test("text: bounds with their centre, the cloud's count and density", () => {
  const box = { center: { pose: { position: { x: 0, y: 0, z: 0.2 }, orientation: { w: 1, x: 0, y: 0, z: 0 } } }, size: { width: 1.2, height: 0.8, depth: 0.4 } };
  assert.equal(boundsText(box), "1.2 × 0.8 × 0.4 m at (0, 0, 0.2)");
  assert.equal(cloudText({ bounds: box, is_dense: true, points: [{}, {}] }), "2 points, dense, 1.2 × 0.8 × 0.4 m at (0, 0, 0.2)");
  assert.equal(cloudText({ is_dense: false, points: [{}] }), "1 point, not dense");
  assert.equal(boundsText(null), null);
});

test("renderers: every standard cloud type recognised, an older layout falls back", { skip: defs ? false : SKIP_REASON }, () => {
  const d = standardDescriber(new RobdefOutline(defs));
  for (const t of [...CLOUD_TYPES, ...CLOUD_PART_TYPES]) {
    const desc = d.describe(t, "com.robotraconteur.pointcloud");
    assert.ok(desc.renderer, `${t} has its renderer`);
    assert.equal(desc.mismatch ?? null, null, `${t}: ${desc.mismatch}`);
  }
  const older = { ...defs };
  older["com.robotraconteur.pointcloud"] = defs["com.robotraconteur.pointcloud"].replace(/struct PointCloudf\n(\s+field BoundingBoxf bounds\n)/, "struct PointCloudf\n");
  const d2 = standardDescriber(new RobdefOutline(older));
  const desc = d2.describe("com.robotraconteur.pointcloud.PointCloudf", "com.robotraconteur.pointcloud");
  assert.equal(desc.renderer ?? null, null);
  assert.match(desc.mismatch, /has no field bounds/);
});
