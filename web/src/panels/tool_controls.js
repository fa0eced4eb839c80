// The tool panel's controls (panels/tool_panel.js): Enable, Disable, Reset errors and Halt, and the
// hold-to-run motions Open, Close, Home and "move to" a position (setf_command), each only when the
// gateway lets this user call its member (robot/access.js) and tool_info's capabilities offer it.
// A motion runs only while its button is held: every way the hold ends (release, pointer lost, window
// blur, hidden tab, page hide, the panel removed, the session closed, tool_state stale or closed, Halt)
// calls halt() once the motion call was answered (tool/tool_state.js ToolHold). The gateway halts the
// tool itself when the page goes away mid-motion (docs/security.md "Motion safety").

import { h, errorText } from "../dom.js";
import { holdButton } from "../robot/hold.js";
import { isStale } from "../robot/status.js";
import { ToolHold, commandRange } from "../tool/tool_state.js";

/**
 * The controls of the panel's `tool` in `box`. Returns { build() (once access and tool_info are
 * known), refresh() (after each state and stale change), release(reason), dispose() }.
 */
export function createToolControls(tool, { el, box, moveBox }) {
  const { obj } = tool;
  const cleanups = [];
  const holdButtons = [];
  const hold = new ToolHold({
    halt: () => obj.halt(),
    onError: (e, what) => { if (!tool.disposed) tool.showError(`${what}: ${errorText(e)}`); },
    onStop: (reason) => {
      el.dataset.hold = "off";
      el.dataset.holdStop = reason;
      for (const b of holdButtons) b.classList.remove("held");
    },
  });
  const release = (reason) => hold.stop(reason);
  const press = (name, call) => {
    tool.showError(null);
    el.dataset.hold = name;
    el.dataset.holds = String(Number(el.dataset.holds ?? 0) + 1);  // for tests: a hold started
    hold.start(name, call);
  };

  // every way the page can lose the operator ends the hold
  const onBlur = () => release("blur");
  const onHidden = () => { if (document.visibilityState === "hidden") release("hidden"); };
  window.addEventListener("blur", onBlur);
  window.addEventListener("pagehide", onBlur);
  document.addEventListener("visibilitychange", onHidden);
  cleanups.push(() => {
    window.removeEventListener("blur", onBlur);
    window.removeEventListener("pagehide", onBlur);
    document.removeEventListener("visibilitychange", onHidden);
  });
  const offClose = obj.$client?.onClose?.(() => release("session closed"));
  if (typeof offClose === "function") cleanups.push(offClose);

  const canMove = () => !!tool.state && !isStale(tool.lastStateMs, Date.now());
  function holdControl(parent, name, label, call, dataset = {}) {
    const b = h("button", { type: "button", class: "small jog tool-hold", text: label, dataset: { action: name, ...dataset } });
    cleanups.push(holdButton(b, () => press(name, call), release));
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
    dispose() {
      release("dispose");
      for (const c of cleanups) c();
    },
  };
}
