// A robot on the official abstract robot base (PyPI robotraconteur-abstract-robot) behind rr-gateway,
// in headless Chromium (issue 41): test/browser/devices/sim_robot.py, a simulated three-joint arm
// whose RobotInfo comes from an info file through the companion library's InfoFileLoader. The page
// shows its device card and robot panel, robot_state_flags by name (Enable in the panel turns "none"
// into "enabled | ready"), the joints named from the RobotInfo, UUIDs as 8-4-4-4-12 text, times as dates, enums by name, capabilities by flag
// name; its plots have no series for UUID bytes or clock fields. Screenshots go to $RR_ARTIFACTS
// (docs/img with RR_DOCS_SCREENSHOTS=1).

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import { settings, startGateway, launchChromium, apiDevices, waitFor } from "./harness.mjs";
import { startDevice, screenshot } from "./std_support.mjs";

const s = settings();
let robot, gateway, browser, page;
const pageErrors = [];

const view = () => page.locator('.device-view[data-device="robot"]');
const card = (name) => view().locator(`.member[data-member="${name}"]`).first();
const ISO = /\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d(\.\d+)?Z/;
const UUID_TEXT = /^[0-9a-f]{8}-[0-9a-f]{4}-[0-9a-f]{4}-[0-9a-f]{4}-[0-9a-f]{12}$/;

/** The names of a plot's series (its readout) in a card. */
const seriesOf = (c) => c.locator(".plot-readout .readout-item").evaluateAll((els) => els.map((e) => e.dataset.series));

before(async () => {
  assert.ok(s.gateway, "RR_GATEWAY must be set");
  robot = await startDevice("sim_robot.py", ["--max-lifetime", "240"]);
  gateway = await startGateway(s, { robot: robot.info.url }, 0, ["--no-demo", "--no-discovery"]);
  await waitFor(async () => (await apiDevices(gateway.base)).find((d) => d.name === "robot")?.state === "connected",
    "robot connected", 30000);
  browser = await launchChromium();
  page = await (await browser.newContext({ viewport: { width: 1366, height: 1000 } })).newPage();
  page.on("pageerror", (e) => pageErrors.push(e));
  await page.goto(`${gateway.base}/#/robot`);
  await card("robot_state").waitFor({ timeout: 60000 });
});

after(async () => {
  if (page) await screenshot(page, "std-robot-end.png", { docs: false }).catch(() => {});
  await browser?.close();
  await gateway?.child.stop();
  await robot?.child.stop();
});

test("device card: name, UUID as text, manufacturer, model, serial, implemented types", async () => {
  const rowsEl = view().locator('[data-panel="device-card"]');
  await waitFor(async () => (await rowsEl.getAttribute("data-loaded")) === "true", "device_info read");
  const row = async (key) => rowsEl.locator(`dd[data-row="${key}"]`).textContent();
  assert.equal(await row("name"), "sim_arm");
  assert.equal(await row("uuid"), robot.info.device_uuid);
  assert.equal(await row("manufacturer"), "rr-gateway tests (0c6f8a3e-2d41-4b7f-9a15-3e8d2b6c4f70)");
  assert.equal(await row("model"), "sim-3r (2e7d9c1b-5a4f-4e3d-8c2b-1a0f9e8d7c65)");
  assert.equal(await row("serial"), "SIM-3R-0001");
  assert.equal(await row("classes"), "robot (serial)");
  assert.match(await row("types"), /com\.robotraconteur\.robotics\.robot\.Robot/);
  // a robot is no camera
  assert.equal(await view().locator('[data-panel="camera"]').count(), 0);
});

test("flags by name: Enable in the robot panel turns 'none' into 'enabled | ready'", async () => {
  const text = () => card("robot_state").locator(".stream output.value").textContent();
  const robotPanel = view().locator('[data-panel="robot"]');
  await waitFor(async () => /robot_state_flags: /.test(await text()), "robot_state shown");
  assert.match(await text(), /robot_state_flags: none[,}]/);
  // the robot panel and the robot_state card share one wire connection: no error on either
  assert.ok(await card("robot_state").locator(".member-error").isHidden(), await card("robot_state").locator(".member-error").textContent());
  await waitFor(async () => (await robotPanel.getAttribute("data-flags")) === "none", "the panel's flags");
  await robotPanel.locator('button[data-action="enable"]').click();
  await waitFor(async () => /robot_state_flags: enabled \| ready[,}]/.test(await text()), "enabled | ready", 15000);
  await waitFor(async () => (await robotPanel.getAttribute("data-flags")) === "enabled | ready", "the panel's flags enabled | ready");
  assert.equal(await robotPanel.locator('dd[data-row="controller_state"]').textContent(), "motor_on");
  assert.match(await robotPanel.locator('dd[data-row="ts"]').textContent(), ISO);
  assert.deepEqual(await robotPanel.locator("table.robot-joints tbody tr").evaluateAll((rows) => rows.map((r) => r.dataset.joint)),
    robot.info.joint_names);
  assert.match(await robotPanel.locator('tr[data-joint="shoulder"]').textContent(), /shoulder0\.00° \(0\.0000 rad\)/);
  assert.equal(await robotPanel.locator(".robot-tool").textContent(), "tool: position (0.7, 0, 0.3) m, rpy (0, 0, 0)°");
  const t = await text();
  assert.match(t, new RegExp(`^\\{ts: ${ISO.source} \\([\\d.]+ m?s ago\\), seqno: \\d+, command_mode: [a-z_]+, operational_mode: [a-z_]+, controller_state: motor_on,`));
  assert.match(t, /kin_chain_tcp: \[position \(0\.7, 0, 0\.3\) m, rpy \(0, 0, 0\)°\]/);
  // advanced_robot_state: the units codes by name (uint8[] of JointPositionUnits), and as units of the positions
  const adv = card("advanced_robot_state").locator(".stream output.value");
  await waitFor(async () => /joint_position_units: /.test(await adv.textContent()), "advanced_robot_state shown");
  assert.match(await adv.textContent(), /joint_position: \[[-\d., ]+\] radian, .*joint_position_units: \[radian, radian, radian\]/);
  // enums by name in properties; capabilities by flag name in robot_info; joint UUIDs as text
  await waitFor(async () => /^[a-z_]+$/.test(await card("command_mode").locator("output.value").textContent()), "command_mode by name");
  const info = card("robot_info").locator("output.value");
  await waitFor(async () => (await info.textContent()).length > 20, "robot_info read");
  const infoText = await info.textContent();
  assert.match(infoText, /robot_capabilities: jog_command \| position_command \| software_reset_errors \| software_enable/);
  assert.match(infoText, /joint_identifier: shoulder \(11111111-2222-4333-8444-555555555501\)/);
  assert.match(infoText, /robot_type: serial/);
  assert.doesNotMatch(infoText, /uuid_bytes/);
  await screenshot(page, "dashboard-robot.png");
  assert.deepEqual(pageErrors.map(String), []);
});

test("no plot series per UUID byte or clock field; times as dates", async () => {
  // robot_state: joints plotted, no ts
  const state = card("robot_state");
  await waitFor(async () => (await seriesOf(state)).includes("joint_position[0]"), "joint_position plotted");
  const stateSeries = await seriesOf(state);
  assert.ok(!stateSeries.some((n) => /(^|\.)ts(\.|$)|uuid|microseconds/.test(n)), `robot_state series: ${stateSeries}`);
  // device_clock_now: DeviceTime holds two clocks with a clock UUID each: only the seqno is a series
  const clock = card("device_clock_now");
  await waitFor(async () => (await seriesOf(clock)).length > 0, "device_clock_now plotted");
  assert.deepEqual(await seriesOf(clock), ["device_seqno"]);
  // the plot's readout is set when a value arrives, the card's text at the next animation frame: wait for the text
  const clockText = await waitFor(async () => (await clock.locator(".stream output.value").textContent()) || false, "device_clock_now's text", 30000);
  assert.match(clockText, new RegExp(`device_ts: ${ISO.source} `));
  assert.match(clockText, new RegExp(`device_utc: ${ISO.source} `));
  // robot_state_sensor_data (a pipe): the sensor header's source identifier as text, not 16 series
  const pipe = card("robot_state_sensor_data");
  await pipe.locator("button", { hasText: /^Connect$/ }).click();
  await waitFor(async () => (await seriesOf(pipe)).includes("robot_state.joint_position[2]"), "sensor data plotted", 15000);
  const pipeSeries = await seriesOf(pipe);
  assert.ok(!pipeSeries.some((n) => /uuid|source_info|\bts\b/.test(n)), `sensor data series: ${pipeSeries}`);
  // as above: the series come with the packet, the card's text with the next animation frame
  const pipeText = await waitFor(async () => (await pipe.locator(".stream output.value").textContent()) || false, "sensor data's text", 30000);
  const source = /source: sim_arm \(([0-9a-f-]+)\)/.exec(pipeText);
  assert.ok(source, `the source identifier as text: ${pipeText.slice(0, 300)}`);
  assert.match(source[1], UUID_TEXT);
  assert.equal(source[1], robot.info.device_uuid);
  assert.match(pipeText, new RegExp(`data_header: \\{ts: ${ISO.source}`));
  assert.deepEqual(pageErrors.map(String), []);
});
