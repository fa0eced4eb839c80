// The robot panel's controls (panels/robot_panel.js): Enable, Disable, Reset errors and Halt, and the
// command-mode switch, each only when the gateway lets this user use its member (robot/access.js) and
// the robot's capabilities allow it. Halt and a mode change end any jog hold first.

import { h, errorText } from "../dom.js";
import { modeText } from "../robot/status.js";

// The command modes the switch offers, with the capability each needs (halt needs none).
const MODES = [["halt", null], ["jog", "jog_command"], ["position_command", "position_command"],
  ["velocity_command", "velocity_command"], ["trajectory", "trajectory_command"], ["homing", "homing_command"]];

/** Fills `controls` for the panel's `robot`; `release(reason)` ends a jog hold. */
export function buildControls(robot, controls, release) {
  const { obj, caps } = robot;
  const modeEnum = robot.enums.mode;
  controls.replaceChildren();
  const action = (name, label, cap) => {
    if (!robot.may(name) || (cap && !caps?.has(cap))) return;
    const b = h("button", { type: "button", class: "small", text: label, dataset: { action: name }, onclick: async () => {
      if (name === "halt") release("halt");
      b.disabled = true;
      try {
        await obj[name]();
        if (!robot.disposed) robot.showError(null);
      } catch (e) {
        if (!robot.disposed) robot.showError(`${name}: ${errorText(e)}`);
      } finally {
        b.disabled = false;
      }
    } });
    controls.append(b);
  };
  action("enable", "Enable", "software_enable");
  action("disable", "Disable", "software_enable");
  action("reset_errors", "Reset errors", "software_reset_errors");
  action("halt", "Halt", null);
  if (robot.may("command_mode", "write") && modeEnum.length) {
    const select = h("select", { name: "command-mode" },
      ...MODES.filter(([, cap]) => !cap || caps?.has(cap)).map(([m]) => h("option", { value: m, text: m })));
    const set = h("button", { type: "button", class: "small", text: "Set mode", dataset: { action: "command_mode" }, onclick: async () => {
      const target = modeEnum.find((e) => e.name === select.value)?.value;
      set.disabled = true;
      release("mode change");
      try {
        // the abstract robot takes a new mode only from halt
        const now = await obj.command_mode.get();
        if (Number(now) !== target && modeText(modeEnum, now) !== "halt" && select.value !== "halt") await obj.command_mode.set(modeEnum.find((e) => e.name === "halt").value);
        await obj.command_mode.set(target);
        if (!robot.disposed) robot.showError(null);
      } catch (e) {
        if (!robot.disposed) robot.showError(`command_mode: ${errorText(e)}`);
      } finally {
        set.disabled = false;
      }
    } });
    controls.append(h("label", { class: "robot-mode" }, "command mode ", select), set);
  }
}
