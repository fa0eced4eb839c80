// The robot panel's 3D view (web/src/robot/view3d.js) on the official abstract robot (issue 42), in
// headless Chromium (WebGL by SwiftShader): two simulated robots behind rr-gateway,
// test/browser/devices/sim_robot.py with its three-joint arm (sim_robot_info.yml) and with a rail,
// turn, lift and wrist (sim_robot_prismatic_info.yml: prismatic joints, a turned flange, a moved
// device_origin_pose). The sims run with --joints-stdin: a JSON line of joint positions written to
// their stdin puts the joints there at once, so the test sets any joint vector without waiting for
// motion and without a client of its own.
// (1) the view's pixels change when a joint moves, and it does not render again while nothing moves;
// (2) for 50 random joint vectors per robot, the pose the page computes from robot_info equals the
//     kin_chain_tcp the driver sent with that joint vector (the driver computes it with
//     general_robotics_toolbox on the Robot RobotRaconteurCompanion makes of the same RobotInfo), within
//     1 mm and 0.1°; (3) a robot_info it cannot use gives a message, and disposed views free their WebGL
//     contexts. Screenshot: docs/img/dashboard-robot-3d.png with RR_DOCS_SCREENSHOTS=1.

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import path from "node:path";
import { createRequire } from "node:module";
import { settings, startGateway, apiDevices, waitFor, ROOT, CHROMIUM_ARGS } from "./harness.mjs";
import { startDevice, screenshot } from "./std_support.mjs";

const s = settings();
let arm, rail, gateway, browser, page;
const pageErrors = [], consoleLines = [];

/** Joint limits of the two info files (the driver's toolbox refuses vectors outside them). */
const LIMITS = {
  robot: [[-3, 3], [-2.5, 2.5], [-3, 3]],
  rail: [[0, 0.8], [-3, 3], [-0.1, 0.4], [-2, 2]],
};

const panel = (device) => page.locator(`.device-view[data-device="${device}"] [data-panel="robot"]`);
const view3d = (device) => panel(device).locator(".robot-view3d");
const data = async (device, key) => JSON.parse((await view3d(device).getAttribute(`data-${key}`)) ?? "null");

/** Puts the sim's joints at q (sim_robot.py --joints-stdin) and waits until the view has drawn them. */
async function moveTo(robot, device, q) {
  robot.child.proc.stdin.write(`${JSON.stringify(q)}\n`);
  await waitFor(async () => {
    const drawn = await data(device, "q");
    return drawn && drawn.length === q.length && drawn.every((x, i) => Math.abs(x - q[i]) < 1e-12);
  }, `${device} drawn at [${q}]`, 15000, 20);
}

/** The canvas's RGBA pixels (copied through a 2D canvas: the WebGL one keeps its drawing buffer). */
function pixels(device) {
  return view3d(device).locator("canvas").evaluate((c) => {
    const copy = document.createElement("canvas");
    copy.width = c.width;
    copy.height = c.height;
    const g = copy.getContext("2d", { willReadFrequently: true });
    g.drawImage(c, 0, 0);
    return Array.from(g.getImageData(0, 0, c.width, c.height).data);
  });
}

/** Deterministic random vectors inside the limits (mulberry32), a margin of 2 % from each limit. */
function randomVectors(limits, count, seed) {
  let a = seed >>> 0;
  const rnd = () => { a = (a + 0x6d2b79f5) >>> 0; let t = Math.imul(a ^ (a >>> 15), 1 | a); t ^= t + Math.imul(t ^ (t >>> 7), 61 | t); return ((t ^ (t >>> 14)) >>> 0) / 4294967296; };
  return Array.from({ length: count }, () => limits.map(([lo, hi]) => lo + (0.02 + 0.96 * rnd()) * (hi - lo)));
}

/** Distance (m) and angle (rad) between two poses given as [x, y, z, qw, qx, qy, qz]. */
function poseDistance(a, b) {
  const dot = Math.abs(a[3] * b[3] + a[4] * b[4] + a[5] * b[5] + a[6] * b[6]) / (Math.hypot(...a.slice(3)) * Math.hypot(...b.slice(3)));
  return { distance: Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]), angle: 2 * Math.acos(Math.min(1, dot)) };
}

before(async () => {
  assert.ok(s.gateway, "RR_GATEWAY must be set");
  [arm, rail] = await Promise.all([
    startDevice("sim_robot.py", ["--joints-stdin", "--max-lifetime", "280"], { stdin: "pipe" }),
    startDevice("sim_robot.py", ["--joints-stdin", "--info", path.join(ROOT, "test/browser/devices/sim_robot_prismatic_info.yml"),
      "--max-lifetime", "280"], { stdin: "pipe" }),
  ]);
  gateway = await startGateway(s, { robot: arm.info.url, rail: rail.info.url }, 0, ["--no-demo", "--no-discovery"]);
  await waitFor(async () => (await apiDevices(gateway.base)).filter((d) => d.state === "connected").length === 2,
    "both robots connected", 30000);
  // WebGL in headless Chromium without a GPU: SwiftShader, which Chromium asks to allow explicitly
  const { chromium } = createRequire(path.join(ROOT, "web/package.json"))("playwright-core");
  browser = await chromium.launch({ executablePath: "/usr/bin/chromium", headless: true,
    args: [...CHROMIUM_ARGS, "--enable-unsafe-swiftshader", "--use-angle=swiftshader"] });
  page = await (await browser.newContext({ viewport: { width: 1366, height: 1000 } })).newPage();
  page.on("pageerror", (e) => pageErrors.push(e));
  page.on("console", (m) => consoleLines.push(`${m.type()}: ${m.text()}`));
  await page.goto(`${gateway.base}/#/robot`);
  await view3d("robot").waitFor({ timeout: 60000 });
});

after(async () => {
  if (page) await screenshot(page, "std-robot3d-end.png", { docs: false }).catch(() => {});
  await browser?.close();
  await gateway?.child.stop();
  await arm?.child.stop();
  await rail?.child.stop();
});

test("the 3D view's pixels change when a joint moves, and it renders nothing while nothing moves", async () => {
  await waitFor(async () => (await view3d("robot").getAttribute("data-state")) !== null, "the view mounted");
  assert.equal(await view3d("robot").getAttribute("data-state"), "ready", await view3d("robot").textContent());
  await moveTo(arm, "robot", [0, 0, 0]);
  const before = await pixels("robot");
  assert.ok(new Set(before.filter((_, i) => i % 4 === 0)).size > 3, "the canvas holds a drawing, not one colour");
  // the robot stands still (the wire still brings states at 50 Hz): no new frame in a second
  const renders = Number(await view3d("robot").getAttribute("data-renders"));
  await page.waitForTimeout(1000);
  assert.equal(Number(await view3d("robot").getAttribute("data-renders")), renders, "rendered again with nothing changed");
  await moveTo(arm, "robot", [0.9, -0.7, 1.2]);
  const after = await pixels("robot");
  assert.equal(after.length, before.length);
  let changed = 0;
  for (let i = 0; i < after.length; i += 4) {
    if (Math.abs(after[i] - before[i]) + Math.abs(after[i + 1] - before[i + 1]) + Math.abs(after[i + 2] - before[i + 2]) > 60) changed++;
  }
  assert.ok(changed > 500, `only ${changed} pixels changed when the joints moved`);
  await moveTo(arm, "robot", [0.6, -0.5, 0.9]);
  await screenshot(panel("robot"), "dashboard-robot-3d.png");
  assert.deepEqual(pageErrors.map(String), []);
});

for (const [device, seed] of [["robot", 11], ["rail", 23]]) {
  test(`${device}: the page's pose from robot_info equals the driver's kin_chain_tcp for 50 random joint vectors`, async () => {
    const robot = device === "robot" ? arm : rail;
    if (device !== "robot") {
      await page.goto(`${gateway.base}/#/${device}`);
      await view3d(device).waitFor({ timeout: 60000 });
    }
    assert.equal(await view3d(device).getAttribute("data-state"), "ready", await view3d(device).textContent());
    let worst = { distance: 0, angle: 0 };
    const reported = [];
    for (const q of randomVectors(LIMITS[device], 50, seed)) {
      await moveTo(robot, device, q);
      const [mine] = await data(device, "tcp");
      const [theirs] = await data(device, "reported-tcp");
      assert.ok(mine && theirs, `poses for [${q}]: ${JSON.stringify({ mine, theirs })}`);
      const d = poseDistance(mine, theirs);
      assert.ok(d.distance < 1e-3 && d.angle < (0.1 * Math.PI) / 180,
        `q = [${q.map((x) => x.toFixed(4))}]: page ${JSON.stringify(mine)} against driver ${JSON.stringify(theirs)}: ${(d.distance * 1000).toFixed(3)} mm, ${((d.angle * 180) / Math.PI).toFixed(3)}°`);
      worst = { distance: Math.max(worst.distance, d.distance), angle: Math.max(worst.angle, d.angle) };
      reported.push(theirs);
    }
    // the driver's poses do differ between vectors (a frozen state would pass the comparison above)
    assert.ok(poseDistance(reported[0], reported[1]).distance > 0.01);
    console.log(`${device}: worst of 50: ${(worst.distance * 1000).toFixed(6)} mm, ${((worst.angle * 180) / Math.PI).toFixed(6)}°`);
    assert.deepEqual(pageErrors.map(String), []);
  });
}

test("a robot_info the view cannot use shows a message; disposed views give their WebGL contexts back", async () => {
  const results = await page.evaluate(async () => {
    const { createRobotView3d } = await import("./src/robot/view3d.js");
    const out = [];
    for (const info of [null, { chains: [] }, { joint_info: [{ joint_type: 1 }], chains: [{ kin_chain_identifier: { name: "old" }, H: [{ x: 0, y: 0, z: 1 }], P: [{ x: 0, y: 0, z: 1 }] }] },
      { joint_info: [{ joint_type: 6 }], chains: [{ H: [{ x: 0, y: 0, z: 1 }], P: [{ x: 0, y: 0, z: 1 }, { x: 0, y: 0, z: 1 }] }] }]) {
      const v = createRobotView3d(document.body, info);
      out.push({ ok: v.ok, text: v.el.textContent, canvases: v.el.querySelectorAll("canvas").length });
      v.dispose();
    }
    // 24 views made and disposed in turn: more than the browser's live-context cap (16)
    const good = { joint_info: [{ joint_type: 1 }], chains: [{ H: [{ x: 0, y: 0, z: 1 }], P: [{ x: 0, y: 0, z: 0.5 }, { x: 0.3, y: 0, z: 0 }] }] };
    for (let i = 0; i < 24; i++) {
      const v = createRobotView3d(document.body, good);
      v.update([i * 0.1]);
      await new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r)));
      if (!v.ok || v.el.dataset.renders !== "1") out.push({ ok: false, text: `view ${i}: renders ${v.el.dataset.renders}`, canvases: 0 });
      v.dispose();
    }
    return out;
  });
  assert.deepEqual(results.map((r) => r.ok), [false, false, false, false]);
  assert.match(results[0].text, /^3D view: robot_info has no kinematic chains$/);
  assert.match(results[1].text, /^3D view: robot_info has no kinematic chains$/);
  assert.match(results[2].text, /^3D view: old: P has 1 vectors, H 1 \(P needs one more\)$/);
  assert.match(results[3].text, /^3D view: chain 0: joint 0 is other: only revolute, continuous and prismatic joints are drawn$/);
  assert.deepEqual(results.map((r) => r.canvases), [0, 0, 0, 0]);
  assert.deepEqual(consoleLines.filter((l) => /Too many active WebGL contexts/i.test(l)), []);
  assert.deepEqual(pageErrors.map(String), []);
});
