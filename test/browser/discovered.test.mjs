// The dashboard's discovered view (web/src/discovered_list.js) in headless Chromium: gateway A runs with
// discovery on and no devices; gateway B (demo devices create and webcam) publishes its node on
// rr+local in the same temporary node directories (the official ROBOTRACONTEUR_*_DIR overrides). A's
// page must list B's node (source "local") with its services, and "Add" on webcam must make a gateway
// device of it that connects over rr+local and opens in the page. Run by ctest
// (test/browser/CMakeLists.txt) with `node --test`; screenshots go to $RR_ARTIFACTS.

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";
import { settings, startGateway, launchChromium, apiDevices, waitFor } from "./harness.mjs";

const s = settings();
const tree = fs.mkdtempSync(path.join(os.tmpdir(), "rr_dash_discover_"));
const env = { ...process.env };
for (const [v, sub] of [["ROBOTRACONTEUR_SYSTEM_RUN_DIR", "sysrun"], ["ROBOTRACONTEUR_SYSTEM_STATE_DIR", "sysstate"],
  ["ROBOTRACONTEUR_SYSTEM_CONFIG_DIR", "sysconfig"], ["ROBOTRACONTEUR_USER_RUN_DIR", "run"], ["ROBOTRACONTEUR_USER_CONFIG_DIR", "config"]])
  env[v] = path.join(tree, sub);
const nameB = `dash.discover.b${process.pid}`;
let a, b, browser, page;
const pageErrors = [];

before(async () => {
  b = await startGateway(s, {}, 0, ["--robotraconteur-nodename", nameB], { local: true, env });
  a = await startGateway(s, {}, 0, ["--no-demo", "--discovery", "--robotraconteur-nodename", `dash.discover.a${process.pid}`], { env });
  browser = await launchChromium();
  page = await browser.newPage({ viewport: { width: 1280, height: 900 } });
  page.on("pageerror", (e) => pageErrors.push(e.message));
});

after(async () => {
  await browser?.close();
  const statuses = [await a?.child.stop(), await b?.child.stop()];
  fs.rmSync(tree, { recursive: true, force: true });
  for (const st of statuses) if (st) assert.equal(st.code, 0, `a gateway exited with ${JSON.stringify(st)}`);
});

test("lists a local node's services and adds one as a device", async () => {
  assert.deepEqual(await apiDevices(a.base), []);
  await page.goto(`${a.base}/`);
  // B's gateway node by its exact NodeName (its demo devices' node NAME.demo is listed too).
  const exact = new RegExp(`^${nameB.replace(/\./g, "\\.")}$`);
  const node = page.locator(".discovered-node").filter({ has: page.locator(".discovered-head .device-name", { hasText: exact }) });
  await node.waitFor({ timeout: 60000 });
  assert.equal(await node.getAttribute("data-source"), "local");
  const webcam = node.locator('li[data-service="webcam"]');
  await webcam.locator("button.add").waitFor({ timeout: 60000 });
  assert.equal(await node.locator('li[data-service="create"] button.add').count(), 1);
  fs.mkdirSync(s.artifacts, { recursive: true });
  await page.screenshot({ path: path.join(s.artifacts, "discovered.png"), fullPage: true });

  await webcam.locator("button.add").click();
  // The device exists, connects over rr+local, and the page opens it.
  const dev = await waitFor(async () => (await apiDevices(a.base)).find((d) => d.name === "webcam" && d.state === "connected"),
    "webcam added and connected", 30000);
  assert.match(dev.url, /^rr\+local:\/\/\/\?nodeid=[0-9a-f-]{36}&service=webcam$/);
  await page.locator('.devices li[data-device="webcam"][data-state="connected"]').waitFor({ timeout: 60000 });
  await waitFor(async () => (await page.evaluate(() => location.hash)) === "#/webcam", "the page opened the new device");
  // The discovered list now names the device serving the service instead of offering "Add".
  await webcam.locator("a.served-by", { hasText: "webcam" }).waitFor({ timeout: 60000 });
  assert.equal(await webcam.locator("button.add").count(), 0);
  await page.screenshot({ path: path.join(s.artifacts, "discovered-added.png"), fullPage: true });
  assert.deepEqual(pageErrors, []);
});
