// Shared by the sensor, laser scanner and point cloud browser tests (std_sensors, std_laser): a
// gateway with logins (alice: operator, bob: viewer; harness.mjs writeOperatorViewerConfig) in front
// of the given devices, a page logged in as one of them, and a device's stdin commands.

import fs from "node:fs";
import os from "node:os";
import path from "node:path";
import { settings, writeOperatorViewerConfig, startGateway, waitFor, apiDevices } from "./harness.mjs";

/** A gateway with logins in front of `devices` ({name: url}); resolves { gateway, tmp, cookie }. */
export async function gatewayWithLogins(devices) {
  const s = settings();
  const tmp = fs.mkdtempSync(path.join(os.tmpdir(), "rr-std-sensors-"));
  const config = writeOperatorViewerConfig(tmp, ["devices:", ...Object.entries(devices).flatMap(([name, url]) => [`  - name: ${name}`, `    url: ${url}`])]);
  const gateway = await startGateway(s, {}, 0, ["--config", config, "--no-demo", "--no-discovery"]);
  const r = await fetch(`${gateway.base}/api/login`, { method: "POST", headers: { "Content-Type": "application/json" }, body: JSON.stringify({ username: "alice", password: "alice-pw" }) });
  if (!r.ok) throw new Error(`login alice: ${r.status}`);
  const cookie = r.headers.get("set-cookie").split(";")[0];
  await waitFor(async () => {
    const list = await fetch(`${gateway.base}/api/devices`, { headers: { cookie } }).then((x) => x.json());
    return Object.keys(devices).every((n) => list.find((d) => d.name === n)?.state === "connected");
  }, `devices ${Object.keys(devices).join(", ")} connected`, 40000);
  return { gateway, tmp, cookie };
}

/** A gateway without logins in front of `devices`; resolves the gateway once they are connected. */
export async function gatewayOpen(devices) {
  const gateway = await startGateway(settings(), devices, 0, ["--no-demo", "--no-discovery"]);
  await waitFor(async () => {
    const list = await apiDevices(gateway.base);
    return Object.keys(devices).every((n) => list.find((d) => d.name === n)?.state === "connected");
  }, `devices ${Object.keys(devices).join(", ")} connected`, 40000);
  return gateway;
}

/**
 * A new context of `browser` logged in as `user` (password `<user>-pw`) at `base`, on `#/<device>`;
 * page errors go to `errors`.
 */
export async function loggedInPage(browser, base, user, device, errors) {
  const context = await browser.newContext({ viewport: { width: 1280, height: 1100 } });
  const page = await context.newPage();
  page.on("pageerror", (e) => errors.push(`${user}: ${e}`));
  await page.goto(`${base}/#/${device}`);
  await page.waitForURL(/\/login\.html/, { timeout: 20000 });
  await page.fill("#login-username", user);
  await page.fill("#login-password", `${user}-pw`);
  await page.click("#login-submit");
  await page.waitForURL((u) => !/login\.html/.test(String(u)), { timeout: 20000 });
  await page.goto(`${base}/#/${device}`);
  return page;
}

/** Writes command `cmd` (JSON) to a device's stdin and resolves its answer line holding `key`. */
export async function command(device, cmd, key) {
  const answer = device.child.jsonLine(key, 15000);
  device.child.proc.stdin.write(`${JSON.stringify(cmd)}\n`);
  return answer;
}

/** The panel `name` of device `device` on `page`. */
export const panelOf = (page, device, name) => page.locator(`.device-view[data-device="${device}"] [data-panel="${name}"]`);
