// The robot panel, for objects implementing com.robotraconteur.robotics.robot.Robot: the state of
// its robot_state wire at a glance (command mode, operational mode, controller state, the state
// flags by name, the time of the state), a table of the joints named from its robot_info (position,
// and the command when there is one) and the tool poses, with Enable, Disable, Reset errors and Halt.
// Each part is there only when the robot has the member with a type the page recognises; the
// generic member view below still shows every member (and drives the robot: jog, trajectories, ...).

import { h, errorText } from "../dom.js";
import { describeMember } from "../views/context.js";
import { fieldText, typedText } from "../std/typed_text.js";
import { formatPose } from "../std/geometry.js";
import { followWire } from "../views/shared_wire.js";
import { mountRobot3d } from "./robot_3d.js";

export const ROBOT = "com.robotraconteur.robotics.robot.Robot";
const UNITS = { radian: "rad", degree: "°", meter: "m" };

/** Joint rows [{ name, position, command }] of a RobotState value, named by `jointNames` (or joint_0, ...). */
export function jointRows(state, jointNames = [], units = []) {
  const q = state?.joint_position;
  if (!q || typeof q.length !== "number") return [];
  const cmd = state.joint_position_command?.length === q.length ? state.joint_position_command : null;
  const num = (x, u) => `${Number(x).toFixed(4)}${u ? ` ${u}` : ""}`;
  return Array.from(q, (x, i) => ({
    name: jointNames[i] || `joint_${i}`,
    position: num(x, units[i]),
    command: cmd ? num(cmd[i], units[i]) : "",
  }));
}

/** Joint names and units of a RobotInfo value (its joint_info list). */
export function jointInfo(info, unitEnum) {
  const joints = Array.isArray(info?.joint_info) ? info.joint_info : [];
  return {
    names: joints.map((j) => j?.joint_identifier?.name || ""),
    units: joints.map((j) => UNITS[unitEnum?.find((e) => e.value === j?.default_units)?.name] ?? ""),
  };
}

export function createRobotPanel(parent, ctx) {
  const { obj, view } = ctx;
  const find = (name, kind) => (obj.$members || []).find((m) => m.name === name && m.kind === kind) || null;
  const described = (m) => (m ? describeMember(view, obj, m) : null);
  let disposed = false;
  const error = h("div", { class: "member-error robot-error", role: "alert", hidden: true });
  const showError = (text) => { error.textContent = text || ""; error.hidden = !text; };
  const summary = h("dl", { class: "robot-state-rows" });
  const joints = h("table", { class: "robot-joints" });
  const poses = h("div", { class: "robot-tcp" });
  const controls = h("div", { class: "camera-controls robot-controls" });
  const el = h("section", { class: "panel robot-panel", dataset: { panel: "robot" } },
    h("h3", { text: "Robot" }), controls, error, summary, joints, poses);
  parent.append(el);

  for (const [name, label] of [["enable", "Enable"], ["disable", "Disable"], ["reset_errors", "Reset errors"], ["halt", "Halt"]]) {
    if (!find(name, "function")) continue;
    const b = h("button", { type: "button", class: "small", text: label, dataset: { action: name }, onclick: async () => {
      b.disabled = true;
      try {
        await obj[name]();
        if (!disposed) showError(null);
      } catch (e) {
        if (!disposed) showError(`${name}: ${errorText(e)}`);
      } finally {
        b.disabled = false;
      }
    } });
    controls.append(b);
  }

  let names = [], units = [];
  const infoMember = find("robot_info", "property");
  if (infoMember) {
    const unitEnum = view?.outline?.types?.get("com.robotraconteur.robotics.joints.JointPositionUnits")?.values;
    obj.robot_info.get().then((info) => { ({ names, units } = jointInfo(info, unitEnum)); }).catch(() => {});
  }

  const stateMember = find("robot_state", "wire");
  const stateType = described(stateMember)?.type;
  let follow = null, latest = null, frame = 0;
  const field = (name) => stateType?.fields?.find((f) => f.name === name);
  function draw() {
    frame = 0;
    const s = latest;
    if (!s || disposed) return;
    const rows = ["ts", "command_mode", "operational_mode", "controller_state", "robot_state_flags"]
      .map((n) => [n, field(n)]).filter(([n, f]) => f && s[n] !== undefined)
      .map(([n, f]) => [n === "ts" ? "time" : n.replace(/^robot_state_/, "").replace(/_/g, " "), fieldText(s, f, stateType, view?.text), n]);
    summary.replaceChildren(...rows.flatMap(([label, text, key]) => [h("dt", { text: label }), h("dd", { text, dataset: { row: key } })]));
    const jr = jointRows(s, names, units);
    joints.replaceChildren(
      h("thead", {}, h("tr", {}, h("th", { text: "joint" }), h("th", { text: "position" }), h("th", { text: jr.some((r) => r.command) ? "command" : "" }))),
      h("tbody", {}, ...jr.map((r) => h("tr", { dataset: { joint: r.name } }, h("td", { text: r.name }), h("td", { text: r.position }), h("td", { text: r.command })))));
    const tcp = Array.isArray(s.kin_chain_tcp) ? s.kin_chain_tcp : [];
    poses.replaceChildren(...tcp.map((p, i) => h("div", { class: "robot-tool", dataset: { chain: String(i) } },
      `${tcp.length > 1 ? `tool ${i}` : "tool"}: ${formatPose(p) ?? typedText(p, null)}`)));
    el.dataset.flags = rows.find(([, , key]) => key === "robot_state_flags")?.[1] ?? "";
  }
  if (stateMember && stateType?.fields && !stateMember.writeonly) {
    // shared with the robot_state card below (one connection per wire), reconnected after a close
    follow = followWire(obj, stateMember.name, {
      onValue: (v) => { latest = v; if (!frame) frame = requestAnimationFrame(draw); },
      onError: (e) => {
        if (disposed) return;
        if (e) showError(`robot_state: ${errorText(e)}`);
        else if (error.textContent.startsWith("robot_state:")) showError(null);
      },
    });
  }

  // ---- 3D view of the robot from its robot_info (web/src/panels/robot_3d.js, web/src/robot/view3d.js) ----
  const view3d = mountRobot3d(el, obj, { infoMember, stateMember });
  // ---- end of the 3D view ----

  return {
    el,
    dispose() {
      disposed = true;
      view3d.dispose();
      if (frame) cancelAnimationFrame(frame);
      follow?.dispose();
      el.remove();
    },
  };
}

export const robotPanel = { name: "robot", order: 20, types: [ROBOT], create: createRobotPanel };
