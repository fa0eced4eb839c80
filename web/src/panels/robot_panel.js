// The robot panel, for objects implementing com.robotraconteur.robotics.robot.Robot: an operator's
// view and controls, put together from parts with one job each, which share one state (`robot`
// below: the enums, robot_info read once, the user's access, the newest robot_state):
//   robot_status.js        robot_state as modes, flag chips, tool poses; stale badge; current_errors
//   robot_controls.js      Enable / Disable / Reset errors / Halt and the command-mode switch
//   robot_jog.js           hold-to-jog (joints and Cartesian), jog speed, the device lock while jogging
//   robot_joints_table.js  the joints named and bounded from robot_info, with their jog buttons
//   robot_move_form.js     "move to" (jog_freespace)
//   robot_3d.js            the 3D view from the same robot_info and robot_state
//
// Moving controls appear only once the gateway said this page's user may use their member
// (robot/access.js) and the robot's capabilities allow them (docs/dashboard.md).

import { h, errorText } from "../dom.js";
import { describeMember } from "../views/context.js";
import { jointModel } from "../robot/joints.js";
import { capabilitySet } from "../robot/status.js";
import { fetchAccess, allows } from "../robot/access.js";
import { locksText } from "../robot/lock_text.js";
import { createRobotStatus } from "./robot_status.js";
import { buildControls } from "./robot_controls.js";
import { createRobotJog } from "./robot_jog.js";
import { createJointsTable } from "./robot_joints_table.js";
import { buildMoveForm } from "./robot_move_form.js";
import { mountRobot3d } from "./robot_3d.js";

export const ROBOT = "com.robotraconteur.robotics.robot.Robot";
const RR_ROBOT = "com.robotraconteur.robotics.robot";

export function createRobotPanel(parent, ctx) {
  const { obj, view } = ctx;
  const find = (name, kind) => (obj.$members || []).find((m) => m.name === name && m.kind === kind) || null;
  const enumValues = (name) => view?.outline?.types?.get(name)?.values ?? [];

  const error = h("div", { class: "member-error robot-error", role: "alert", hidden: true });
  const staleBadge = h("span", { class: "badge robot-stale", dataset: { state: "closed" }, text: "stale", hidden: true });
  const summary = h("dl", { class: "robot-state-rows" });
  const errorsBox = h("ul", { class: "robot-current-errors", hidden: true });
  const controls = h("div", { class: "camera-controls robot-controls" });
  const lockBox = h("div", { class: "robot-lock", hidden: true });
  const lockHolder = h("span", { class: "robot-lock-holder" });
  // the 3D view mounts here (panels/robot_3d.js), last: it appears only once three.js has loaded, and
  // above the jog buttons it would push them away from a pointer about to press one
  const view3dBox = h("div", { class: "robot-view3d-box" });
  const joints = h("table", { class: "robot-joints" });
  const jogBox = h("div", { class: "robot-jog", hidden: true });
  const cartBox = h("div", { class: "robot-cartesian", hidden: true });
  const moveForm = h("form", { class: "robot-move", hidden: true });
  const poses = h("div", { class: "robot-tcp" });
  const el = h("section", { class: "panel robot-panel", tabindex: "0", dataset: { panel: "robot", jog: "off" } },
    h("h3", {}, "Robot ", staleBadge), controls, lockBox, error, summary, errorsBox, jogBox, joints, cartBox, moveForm, poses, view3dBox);
  parent.append(el);

  /** What the parts share. */
  const robot = {
    obj, view, find,
    enums: {
      mode: enumValues(`${RR_ROBOT}.RobotCommandMode`),
      op: enumValues(`${RR_ROBOT}.RobotOperationalMode`),
      ctrl: enumValues(`${RR_ROBOT}.RobotControllerState`),
      flag: enumValues(`${RR_ROBOT}.RobotStateFlags`),
      cap: enumValues(`${RR_ROBOT}.RobotCapabilities`),
      unit: enumValues("com.robotraconteur.robotics.joints.JointPositionUnits"),
    },
    disposed: false,
    access: null,        // the gateway's answer (robot/access.js), null until it came
    caps: null,          // Set of RobotCapabilities names, null until robot_info was read
    model: [],           // jointModel of robot_info
    state: null,         // the newest robot_state
    lastStateMs: 0,
    showError(text) { error.textContent = text || ""; error.hidden = !text; },
    may(member, op = "call") {
      return !!(robot.access && find(member, op === "write" ? "property" : "function") && allows(robot.access, member, op));
    },
    canJog() { return !!robot.caps?.has("jog_command") && robot.may("jog_joint"); },
  };
  const cleanups = [];

  const jog = createRobotJog(robot, { el, jogBox, lockBox, lockHolder, cartBox });
  const table = createJointsTable(robot, jog, joints);
  const stateMember = find("robot_state", "wire");
  const stateType = stateMember ? describeMember(view, obj, stateMember)?.type : null;
  const status = createRobotStatus(robot, { el, staleBadge, summary, errorsBox, poses }, stateType, () => jog.refresh());

  // ---- robot_state: one wire subscription shared with the 3D view and the robot_state card ----
  let follow = null, frame = 0;
  function draw() {
    frame = 0;
    if (!robot.state || robot.disposed) return;
    status.draw();
    table.render(false);
    jog.refresh();
  }
  if (stateMember && stateType?.fields && !stateMember.writeonly) {
    follow = ctx.live.followWire(stateMember.name, {
      onValue: (v) => { robot.state = v; robot.lastStateMs = Date.now(); status.markStale(); if (!frame) frame = requestAnimationFrame(draw); },
      onError: (e) => {
        if (robot.disposed) return;
        if (e) { robot.showError(`robot_state: ${errorText(e)}`); jog.release("robot_state closed"); }
        else if (error.textContent.startsWith("robot_state:")) robot.showError(null);
      },
    });
  }
  status.markStale();

  // ---- the locks the gateway reports for this device ----
  const showLocks = () => {
    const d = ctx.devices?.device?.(ctx.device);
    const text = locksText(d?.locks);
    lockHolder.textContent = text ? ` (${text})` : "";
    el.dataset.locks = text;
  };
  if (ctx.devices?.addEventListener) {
    ctx.devices.addEventListener("update", showLocks);
    cleanups.push(() => ctx.devices.removeEventListener("update", showLocks));
  }
  showLocks();

  // ---- robot_info (read once, for the joints, the capabilities and the 3D view) and access ----
  const infoMember = find("robot_info", "property");
  const info = infoMember ? obj.robot_info.get() : Promise.resolve(null);
  const infoRead = info.then((i) => {
    robot.model = i ? jointModel(i, robot.enums.unit) : [];
    robot.caps = i ? capabilitySet(robot.enums.cap, i.robot_capabilities) : new Set();
  }, (e) => { robot.caps = new Set(); if (!robot.disposed) robot.showError(`robot_info: ${errorText(e)}`); });
  const accessRead = ctx.device
    ? fetchAccess(ctx.device, ctx.session?.username ?? null).then((a) => { robot.access = a; })
      .catch((e) => { robot.access = null; if (!robot.disposed) robot.showError(`${e.message}: no controls`); })
    : Promise.resolve().then(() => { robot.access = { members: null }; });
  Promise.all([infoRead, accessRead]).then(() => {
    if (robot.disposed) return;
    const access = robot.access;
    el.dataset.access = access ? (access.members === null ? "all" : "checked") : "none";
    buildControls(robot, controls, jog.release);
    const jogging = jog.build();
    buildMoveForm(robot, moveForm, jogging && robot.may("jog_freespace"));
    table.render(true);
    jog.refresh();
    el.dataset.ready = "true";
  });
  table.render(true);

  const view3d = mountRobot3d(view3dBox, { live: ctx.live, info: infoMember ? info : null, stateMember });

  return {
    el,
    /** Ends any hold now (for tests and the page). */
    stopJog: (reason = "stopped") => jog.release(reason),
    dispose() {
      robot.disposed = true;
      jog.dispose();
      view3d.dispose();
      if (frame) cancelAnimationFrame(frame);
      follow?.dispose();
      status.dispose();
      for (const c of cleanups) c();
      el.remove();
    },
  };
}

export const robotPanel = { name: "robot", order: 20, types: [ROBOT], create: createRobotPanel };
