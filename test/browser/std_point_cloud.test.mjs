// Standard point cloud sensors behind rr-gateway, in headless Chromium (issue 54): test/browser/devices/
// point_cloud.py on the official library sees a table with a red box, a green ball and a blue post
// (10,000 points at 5 Hz) as a PointCloudSensor, a PointCloud2Sensor (intensity and colour per point)
// and their Part variants (each cloud in three parts). The gateway has logins: alice (operator) and bob
// (viewer). Checked: the sensor's info as sent; every point drawn, in the device's own colours (the
// view passes colours through unchanged, so the box's 0xE62828 is on screen as exactly that), by height
// and by intensity through the jet map; the drawing changing as the ball rolls; parts put back into
// whole clouds; Capture and the parameters for the operator only; a sensor without its pipe falling back
// to the generic view and one without the PointCloud2 pipe using the other; no page error.
// Screenshots to $RR_ARTIFACTS (docs/img with RR_DOCS_SCREENSHOTS=1).

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import fs from "node:fs";
import { settings, launchChromium, waitFor } from "./harness.mjs";
import { startDevice, screenshot } from "./std_support.mjs";
import { gatewayWithLogins, loggedInPage, panelOf, command } from "./std_sensor_support.mjs";
import { jetTable } from "../../web/src/std/colormap.js";

const s = settings();
let clouds, trimmed, gateway, tmp, browser, operator;
const pageErrors = [];
const panel = (page, device) => panelOf(page, device, "point-cloud");
const BOX = [230, 40, 40], BALL = [40, 200, 60], POST = [50, 90, 230], TABLE = [150, 150, 150];
const jet = (t) => { const j = jetTable(), i = Math.round(t * 255) * 3; return [j[i], j[i + 1], j[i + 2]]; };

/** How many pixels of the panel's WebGL canvas have each of `colors` exactly. */
function colorCounts(p, colors) {
  return p.locator("canvas.cloud-canvas").evaluate((c, colors) => {
    const copy = document.createElement("canvas");
    copy.width = c.width;
    copy.height = c.height;
    const g = copy.getContext("2d", { willReadFrequently: true });
    g.drawImage(c, 0, 0);
    const px = g.getImageData(0, 0, copy.width, copy.height).data;
    const counts = colors.map(() => 0);
    for (let i = 0; i < px.length; i += 4) {
      for (let k = 0; k < colors.length; k++) {
        if (px[i] === colors[k][0] && px[i + 1] === colors[k][1] && px[i + 2] === colors[k][2]) counts[k]++;
      }
    }
    return counts;
  }, colors);
}

/** Waits until the panel drew `more` clouds after now. */
async function moreClouds(p, more = 2, what = "clouds drawn") {
  const n = Number(await p.getAttribute("data-clouds"));
  await waitFor(async () => Number(await p.getAttribute("data-clouds")) >= n + more, what, 30000);
}

before(async () => {
  assert.ok(s.gateway, "RR_GATEWAY must be set");
  clouds = await startDevice("point_cloud.py", ["--hold", "--points", "10000", "--rate", "5", "--max-lifetime", "280"], { stdin: "pipe" });
  trimmed = await startDevice("point_cloud.py", ["--hold", "--services", "cloud,cloud2", "--points", "2000",
    "--without-member", "point_cloud_sensor_data", "--max-lifetime", "280"]);
  const u = clouds.info.urls;
  ({ gateway, tmp } = await gatewayWithLogins({ cloud: u.cloud, cloud2: u.cloud2, parts: u.parts, parts2: u.parts2,
    trimmed: trimmed.info.urls.cloud, trimmed2: trimmed.info.urls.cloud2 }));
  browser = await launchChromium();
  operator = await loggedInPage(browser, gateway.base, "alice", "cloud2", pageErrors);
  await panel(operator, "cloud2").waitFor({ timeout: 60000 });
});

after(async () => {
  if (operator) await screenshot(operator, "std-point-cloud-end.png", { docs: false }).catch(() => {});
  await browser?.close();
  await gateway?.child.stop();
  await clouds?.child.stop();
  await trimmed?.child.stop();
  if (tmp) fs.rmSync(tmp, { recursive: true, force: true });
});

test("the sensor's info and every point of the cloud, in the device's own colours", async () => {
  const p = panel(operator, "cloud2");
  await waitFor(async () => (await p.getAttribute("data-info")) === "read", "point_sensor_info read");
  const row = (k) => p.locator(`dd[data-row="${k}"]`).textContent();
  assert.equal(await row("bounds"), "1.2 × 0.8 × 0.4 m at (0, 0, 0.2)");
  assert.equal(await row("resolution"), "0.005 m");
  assert.equal(await p.getAttribute("data-pipe"), "point_cloud2_sensor_data");
  await waitFor(async () => Number(await p.getAttribute("data-clouds")) >= 2, "two clouds drawn", 30000);
  assert.equal(await p.getAttribute("data-points"), "10000");
  assert.equal(await p.getAttribute("data-color-mode"), "rgb");
  assert.match(await p.locator(".cloud-status").textContent(),
    /^10000 points \(point_cloud2_sensor_data\), coloured by rgb; [\d.]+ clouds\/s received, [\d.]+ drawn.*; copy [\d.]+ ms, colour [\d.]+ ms \(worker\); seqno \d+$/);
  // each object on screen in exactly its colour
  let counts;
  await waitFor(async () => (counts = await colorCounts(p, [BOX, BALL, POST, TABLE])).every((n) => n > 30), "every object drawn in its colour", 20000)
    .catch(() => {});
  assert.ok(counts.every((n) => n > 30), `pixels of box, ball, post, table: ${counts}`);
  await screenshot(p, "dashboard-point-cloud.png");
  assert.deepEqual(pageErrors, []);
});

test("colour by height and by intensity: the jet map over the cloud's span", async () => {
  const p = panel(operator, "cloud2");
  const select = p.locator("select.cloud-color");
  await select.selectOption("height");
  await waitFor(async () => (await p.getAttribute("data-color-mode")) === "height", "coloured by height", 20000);
  // the table (z = 0, the lowest) in jet(0), the post's top (0.4 m, the highest) in jet(1); no box red
  let counts;
  await waitFor(async () => { counts = await colorCounts(p, [jet(0), jet(1), BOX]); return counts[0] > 100 && counts[1] > 0 && counts[2] === 0; },
    "table and post top in the jet map", 20000).catch(() => {});
  assert.ok(counts[0] > 100 && counts[1] > 0 && counts[2] === 0, `jet(0), jet(1), box red: ${counts}`);
  await select.selectOption("intensity");
  await waitFor(async () => (await p.getAttribute("data-color-mode")) === "intensity", "coloured by intensity", 20000);
  // intensities 40 (table) .. 200 (box): the table in jet(0), the box in jet(1), the ball (120) in jet(0.5)
  await waitFor(async () => { counts = await colorCounts(p, [jet(0), jet(1), jet(0.5)]); return counts.every((n) => n > 30); },
    "table, box and ball by intensity", 20000).catch(() => {});
  assert.ok(counts.every((n) => n > 30), `jet(0), jet(1), jet(0.5): ${counts}`);
  await select.selectOption("auto");
  await waitFor(async () => (await p.getAttribute("data-color-mode")) === "rgb", "back to the device's colours", 20000);
});

test("the drawing changes as the ball rolls (newest cloud wins)", async () => {
  const p = panel(operator, "cloud2");
  const canvas = p.locator("canvas.cloud-canvas");
  await moreClouds(p, 2, "clouds drawn while held");
  await canvas.evaluate(async (c) => {
    const copy = document.createElement("canvas");
    copy.width = c.width; copy.height = c.height;
    const g = copy.getContext("2d", { willReadFrequently: true });
    g.drawImage(c, 0, 0);
    c.firstPixels = g.getImageData(0, 0, c.width, c.height).data;
  });
  assert.deepEqual(await command(clouds, { roll: true }, "rolling"), { rolling: true });
  let changed = 0;
  await waitFor(async () => {
    changed = await canvas.evaluate((c) => {
      const copy = document.createElement("canvas");
      copy.width = c.width; copy.height = c.height;
      const g = copy.getContext("2d", { willReadFrequently: true });
      g.drawImage(c, 0, 0);
      const now = g.getImageData(0, 0, c.width, c.height).data;
      let k = 0;
      for (let i = 0; i < now.length; i += 4) if (now[i] !== c.firstPixels[i] || now[i + 1] !== c.firstPixels[i + 1]) k++;
      return k;
    });
    return changed > 50;
  }, "pixels changed as the ball rolled", 30000).catch(() => {});
  assert.ok(changed > 50, `${changed} pixels changed`);
  assert.deepEqual(await command(clouds, { hold: true }, "rolling"), { rolling: false });
});

test("a PointCloudSensor's positions coloured by height; parts put back into whole clouds", async () => {
  await operator.goto(`${gateway.base}/#/cloud`);
  const p = panel(operator, "cloud");
  await waitFor(async () => Number(await p.getAttribute("data-clouds")) >= 2, "plain clouds drawn", 30000);
  assert.equal(await p.getAttribute("data-pipe"), "point_cloud_sensor_data");
  assert.equal(await p.getAttribute("data-points"), "10000");
  assert.equal(await p.getAttribute("data-color-mode"), "height");

  for (const [device, pipe, mode] of [["parts", "point_cloud_sensor_data", "height"], ["parts2", "point_cloud2_sensor_data", "rgb"]]) {
    await operator.goto(`${gateway.base}/#/${device}`);
    const q = panel(operator, device);
    await waitFor(async () => Number(await q.getAttribute("data-clouds")) >= 2, `${device}: whole clouds drawn`, 30000);
    assert.equal(await q.getAttribute("data-pipe"), pipe);
    assert.equal(await q.getAttribute("data-points"), "10000");
    assert.equal(await q.getAttribute("data-color-mode"), mode);
    assert.doesNotMatch(await q.locator(".cloud-status").textContent(), /incomplete/, `${device}: no cloud begun and left unfinished`);
  }
  assert.deepEqual(pageErrors, []);
});

test("Capture and parameters: the operator's work, the viewer has none", async () => {
  for (const device of ["cloud2", "parts2"]) {
    await operator.goto(`${gateway.base}/#/${device}`);
    const p = panel(operator, device);
    await waitFor(async () => (await p.getAttribute("data-access")) === "checked", `${device}: access read`, 30000);
    const capture = p.locator('button[data-action="capture_point_cloud2"]');
    await capture.click();
    await waitFor(async () => (await p.getAttribute("data-captures")) === "1", `${device}: the captured cloud drawn`, 30000);
    assert.equal(await p.getAttribute("data-shown"), "capture_point_cloud2");
    assert.equal(await p.getAttribute("data-points"), "10000");
    // the live clouds wait until Live
    const received = Number(await p.getAttribute("data-received"));
    await waitFor(async () => Number(await p.getAttribute("data-received")) >= received + 2, `${device}: clouds still received`, 30000)
      .catch(async (e) => { throw new Error(`${e.message}: ${await p.locator(".cloud-status").textContent()} ${await p.locator(".cloud-error").textContent()} received ${await p.getAttribute("data-received")}`); });
    assert.equal(await p.getAttribute("data-shown"), "capture_point_cloud2");
    await p.locator('button[data-action="live"]').click();
    await waitFor(async () => (await p.getAttribute("data-shown")) === "point_cloud2_sensor_data", `${device}: live again`, 30000);
  }
  const p = panel(operator, "parts2");
  const params = p.locator('[data-panel-part="params"]');
  assert.equal(await params.locator("input.param-name").inputValue(), "exposure");
  const set = clouds.child.jsonLine("param_set", 15000);
  await params.locator("input.param-value").fill("12.5");
  await params.locator('button[data-action="setf_param"]').click();
  assert.deepEqual(await set, { param_set: "exposure", value: 12.5 });
  await params.locator('button[data-action="getf_param"]').click();
  await waitFor(async () => (await params.locator(".param-result").textContent()) === "12.5", "exposure read back");

  const viewer = await loggedInPage(browser, gateway.base, "bob", "cloud2", pageErrors);
  const vp = panel(viewer, "cloud2");
  await waitFor(async () => (await vp.getAttribute("data-access")) === "checked", "viewer's access read", 30000);
  await waitFor(async () => Number(await vp.getAttribute("data-clouds")) >= 1, "the viewer sees clouds", 30000);
  assert.equal(await vp.locator('button[data-action="capture_point_cloud2"]').count(), 0);
  assert.equal(await vp.locator('[data-panel-part="params"]').count(), 0);
  await viewer.context().close();
  assert.deepEqual(pageErrors, []);
});

test("a sensor without its pipe: the generic view; without the PointCloud2 pipe: the other one", async () => {
  await operator.goto(`${gateway.base}/#/trimmed`);
  const p = panel(operator, "trimmed");
  await p.waitFor({ timeout: 60000 });
  await waitFor(async () => (await p.getAttribute("data-fallback")) === "true", "fallback", 20000);
  assert.match(await p.locator(".cloud-fallback").textContent(), /no point cloud pipe of a standard cloud type/);
  assert.equal(await p.locator("canvas.cloud-canvas").count(), 0);
  // the generic member view below still lists the sensor's members
  await operator.locator('.device-view[data-device="trimmed"] section.member[data-member="capture_point_cloud"]').waitFor({ timeout: 60000 });

  await operator.goto(`${gateway.base}/#/trimmed2`);
  const q = panel(operator, "trimmed2");
  await waitFor(async () => Number(await q.getAttribute("data-clouds")) >= 1, "trimmed PointCloud2Sensor drawn", 30000);
  assert.equal(await q.getAttribute("data-pipe"), "point_cloud2_sensor_data");
  assert.equal(await q.getAttribute("data-points"), "2000");
  assert.deepEqual(pageErrors, []);
});
