// The planning panel (issue 54): the alpha planning types as a readable view, on a planner served by the
// official library with the draft definitions from $RR_SHARED_DIR (test/browser/devices/planning.py)
// behind rr-gateway with logins: planner_info's algorithms; the scene opened through the Planner's
// `scene` objref: its info, root link, joint positions and the tree of links from the root down, each
// joint with its type, the robot model's links marked. Skipped (77) without the shared definitions.

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import fs from "node:fs";
import path from "node:path";
import { ROOT, launchChromium, waitFor } from "./harness.mjs";
import { startDevice, screenshot } from "./std_support.mjs";
import { gatewayWithLogins, loggedInPage, panelOf } from "./std_sensor_support.mjs";

const shared = process.env.RR_SHARED_DIR || path.resolve(ROOT, "../shared");
const defs = path.join(shared, "robdef-standard/group2/com.robotraconteur.a1.robotics.planning.robdef");
const skip = fs.existsSync(defs) ? false : `alpha planning definitions missing: ${defs} (set RR_SHARED_DIR)`;
let planner, gw, browser;
const pageErrors = [];

before(async () => {
  if (skip) return;
  planner = await startDevice("planning.py", ["--max-lifetime", "200"], { env: { ...process.env, RR_SHARED_DIR: shared } });
  gw = await gatewayWithLogins({ planner: planner.info.url });
  browser = await launchChromium();
});

after(async () => {
  await browser?.close();
  await gw?.gateway.child.stop();
  await planner?.child.stop();
  if (gw?.tmp) fs.rmSync(gw.tmp, { recursive: true, force: true });
});

test("planning: algorithms, the scene's info, joint positions and its tree of links and joints", { skip }, async () => {
  const page = await loggedInPage(browser, gw.gateway.base, "bob", "planner", pageErrors);
  const p = panelOf(page, "planner", "planning");
  await p.waitFor({ timeout: 60000 });
  await waitFor(async () => (await p.getAttribute("data-ready")) === "true", "planning panel read", 40000);
  const row = (k) => p.locator(`dd[data-row="${k}"]`).textContent();
  assert.equal(await p.locator(".planning-error").textContent(), "");
  assert.equal(await row("algorithms"), "ompl_rrt: sampling-based, collision-free; joint_line: straight line in joint space");
  assert.equal(await row("scene"), "cell: work cell 3");
  assert.equal(await row("root_link_name"), "world");
  assert.equal(await row("joint_position"), "joint_1 0.1000; joint_2 -0.2000");
  assert.equal(await row("links"), "6 of 6 placed, models robot");
  assert.equal(await p.locator(".planning-tree").textContent(), [
    "world",
    "  table_mount (other) → table",
    "    base_mount (other) → robot_base [robot]",
    "      joint_1 (revolute) → link_1 [robot]",
    "        joint_2 (revolute) → link_2 [robot]",
    "          flange (other) → tool0 [robot]",
  ].join("\n"));
  await screenshot(p, "dashboard-planning.png");
  await page.context().close();
  assert.deepEqual(pageErrors, []);
});
