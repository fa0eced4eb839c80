// The tool panel's controls (panels/tool_panel.js): Enable, Disable, Reset errors and Halt, and the
// hold-to-run motions Open, Close, Home and "move to" a position (setf_command), each only when the
// gateway lets this user call its member (robot/access.js) and tool_info's capabilities offer it.
// A motion runs only while its button is held (the shared hold-to-run helper hold/hold_to_run.js): every
// way the hold ends (release, pointer lost, window blur, hidden tab, page hide, the panel removed, the
// session closed, tool_state stale or closed, Halt) calls halt() once the motion call was answered
// (tool/tool_state.js ToolHold). The gateway halts the
// tool itself when the page goes away mid-motion (docs/security.md "Motion safety").

import { h, errorText } from "../dom.js";
import { HoldToRun } from "../hold/hold_to_run.js";
import { createGamepadControl, hasGamepadApi } from "./gamepad_control.js";
import { isStale } from "../robot/status.js";
import { ToolHold, commandRange } from "../tool/tool_state.js";

/**
 * The controls of the panel's `tool` in `box`. Returns { build() (once access and tool_info are
 * known), refresh() (after each state and stale change), release(reason), dispose() }.
 */
export function createToolControls(tool, { el, box, moveBox }) {
  const { obj } = tool;
  const hold = new ToolHold({
    halt: () => obj.halt(),
    onError: (e, what) => { if (!tool.disposed) tool.showError(`${what}: ${errorText(e)}`); },
    onStop: (reason) => run.stopped(reason),
  });
  // the page's end of every hold (hold/hold_to_run.js), shared with the robot panel's jog
  const run = new HoldToRun({
    motion: { start: (c) => hold.start(c.name, c.call), stop: (reason) => hold.stop(reason), get active() { return hold.active; } },
    client: obj.$client,
    onStart: (c) => {
      tool.showError(null);
      el.dataset.hold = c.name;
      el.dataset.holds = String(Number(el.dataset.holds ?? 0) + 1);  // for tests: a hold started
    },
    onStop: (reason) => {
      el.dataset.hold = "off";
      el.dataset.holdStop = reason;
    },
  });
  const release = (reason) => run.release(reason);
  const holdButtons = [];
  let gamepad = null;  // "move with a gamepad" (panels/gamepad_control.js)

  const canMove = () => !!tool.state && !isStale(tool.lastStateMs, Date.now());
  function holdControl(parent, name, label, call, dataset = {}) {
    const b = run.button(h("button", { type: "button", class: "small jog tool-hold", text: label, dataset: { action: name, ...dataset } }), () => ({ name, call }));
    holdButtons.push(b);
    parent.append(b);
    return b;
  }
  function action(name, label, cap) {
    if (!tool.may(name) || (cap && !tool.caps.has(cap))) return;
    const b = h("button", { type: "button", class: "small", text: label, dataset: { action: name }, onclick: async () => {
      if (name === "halt" || name === "disable") release(name);
      b.disabled = true;
      try {
        await obj[name]();
        if (!tool.disposed) tool.showError(null);
      } catch (e) {
        if (!tool.disposed) tool.showError(`${name}: ${errorText(e)}`);
      } finally {
        b.disabled = false;
      }
    } });
    box.append(b);
  }

  function build() {
    run.forgetButtons(holdButtons);
    holdButtons.length = 0;
    box.replaceChildren();
    action("enable", "Enable", "software_enable");
    action("disable", "Disable", "software_enable");
    action("reset_errors", "Reset errors", "software_reset_errors");
    action("halt", "Halt", null);
    const openClose = tool.caps.has("open_close_command") || tool.caps.has("continuous_command");
    if (openClose && tool.may("open")) holdControl(box, "open", "Open (hold)", () => obj.open());
    if (openClose && tool.may("close")) holdControl(box, "close", "Close (hold)", () => obj.close());
    if (tool.caps.has("homing_command") && tool.may("home")) holdControl(box, "home", "Home (hold)", () => obj.home());
    const range = commandRange(tool.info);
    moveBox.hidden = !(range && tool.caps.has("continuous_command") && tool.may("setf_command"));
    if (!moveBox.hidden) {
      const [lo, hi] = range;
      const input = h("input", { type: "number", name: "tool-command", min: String(lo * 1000), max: String(hi * 1000), step: "0.1",
        value: String(Number(((lo + hi) * 500).toFixed(1))), "aria-label": "position in mm" });
      moveBox.replaceChildren(h("label", {}, "move to ", input, " mm"));
      holdControl(moveBox, "setf_command", "Move (hold)", () => {
        const mm = Number(input.value);
        if (!Number.isFinite(mm) || mm < lo * 1000 || mm > hi * 1000) throw new Error(`enter a position from ${lo * 1000} to ${hi * 1000} mm`);
        return obj.setf_command(mm / 1000);
      });
      moveBox.append(h("span", { class: "hint", text: "the tool moves only while a (hold) button is held" }));
    }
    const padBindings = toolBindings(tool, obj);
    if (padBindings.length && hasGamepadApi()) {
      gamepad ??= createGamepadControl(run, {
        what: "move",
        bindings: () => padBindings,
        press: (b) => { if (!canMove()) return false; run.press(() => b.command, "gamepad"); return true; },
      });
      box.append(gamepad.el);
    }
    refresh();
  }

  function refresh() {
    const on = canMove();
    const why = on ? "" : !tool.state ? "no tool state" : "tool state is stale";
    for (const b of holdButtons) { b.disabled = !on; b.title = why; }
    if (!on && hold.active) release("stale");
  }

  return {
    build, refresh, release,
    get holding() { return hold.active; },
    dispose() { gamepad?.dispose(); run.dispose(); },
  };
}

/** The tool's motions on a standard gamepad: A holds Close, B holds Open (each when offered). */
function toolBindings(tool, obj) {
  const openClose = tool.caps.has("open_close_command") || tool.caps.has("continuous_command");
  const out = [];
  if (openClose && tool.may("close")) out.push({ id: "close", button: 0, command: { name: "close", call: () => obj.close() } });
  if (openClose && tool.may("open")) out.push({ id: "open", button: 1, command: { name: "open", call: () => obj.open() } });
  return out;
}
