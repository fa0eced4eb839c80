// The robot panel's status (panels/robot_panel.js): the newest robot_state as an operator reads it
// (time, command mode, operational mode, controller state, the state flags as coloured chips, the tool
// poses), a "stale" badge when no state came for 1 s, and the robot's current_errors, read every 2 s
// while the panel is shown.

import { h } from "../dom.js";
import { formatPose } from "../std/geometry.js";
import { fieldText } from "../std/typed_text.js";
import { formatFlags } from "../std/enums.js";
import { flagChips, modeText, isStale, STALE_MS } from "../robot/status.js";

const ERRORS_POLL_MS = 2000;

/**
 * The status parts of the panel's `robot`: `parts` { el (the panel), staleBadge, summary, errorsBox,
 * poses }; `stateType` the robot_state wire's descriptor; `onStale()` after the stale mark changes.
 * Returns { draw() (the newest robot.state), markStale(), dispose() }.
 */
export function createRobotStatus(robot, { el, staleBadge, summary, errorsBox, poses }, stateType, onStale) {
  const { obj, view, enums } = robot;
  const timers = [];

  function draw() {
    const s = robot.state;
    if (!s) return;
    const dd = (key, ...content) => h("dd", { dataset: { row: key } }, ...content);
    const rows = [];
    const tsField = stateType.fields.find((f) => f.name === "ts");
    if (tsField && s.ts !== undefined) rows.push(["time", dd("ts", fieldText(s, tsField, stateType, view?.text))]);
    rows.push(["command mode", dd("command_mode", modeText(enums.mode, s.command_mode))]);
    rows.push(["operational mode", dd("operational_mode", modeText(enums.op, s.operational_mode))]);
    rows.push(["controller state", dd("controller_state", modeText(enums.ctrl, s.controller_state))]);
    const chips = flagChips(enums.flag, s.robot_state_flags ?? 0);
    rows.push(["flags", dd("robot_state_flags", ...(chips.length ? chips.map((c) => h("span", { class: `chip chip-${c.tone}`, text: c.name, dataset: { flag: c.name } })) : ["none"]))]);
    summary.replaceChildren(...rows.flatMap(([label, d]) => [h("dt", { text: label }), d]));
    el.dataset.flags = formatFlags(enums.flag, s.robot_state_flags ?? 0);
    const tcp = Array.isArray(s.kin_chain_tcp) ? s.kin_chain_tcp : s.kin_chain_tcp?.length ? Array.from(s.kin_chain_tcp) : [];
    poses.replaceChildren(...tcp.map((p, i) => h("div", { class: "robot-tool", dataset: { chain: String(i) } },
      `${tcp.length > 1 ? `tool ${i}` : "tool"}: ${formatPose(p) ?? "(invalid pose)"}`)));
  }

  function markStale() {
    const stale = isStale(robot.lastStateMs, Date.now());
    if (String(stale) === el.dataset.stale) return;
    el.dataset.stale = String(stale);
    staleBadge.hidden = !stale;
    staleBadge.textContent = robot.lastStateMs ? `stale: no robot_state for over ${STALE_MS / 1000} s` : "no robot_state yet";
    onStale();
  }
  timers.push(setInterval(markStale, 250));

  // current_errors (a property, nolock)
  if (robot.find("current_errors", "property")) {
    let busy = false;
    const readErrors = async () => {
      if (busy || robot.disposed) return;
      busy = true;
      try {
        const list = await obj.current_errors.get();
        const items = Array.isArray(list) ? list : list ? Array.from(list.values?.() ?? []) : [];
        errorsBox.replaceChildren(...items.map((m) => h("li", { text: [m?.title, m?.message].filter(Boolean).join(": ") || "(error without text)" })));
        errorsBox.hidden = !items.length;
      } catch {
        errorsBox.hidden = true;  // a driver without current_errors (or not allowed to read it)
      } finally {
        busy = false;
      }
    };
    timers.push(setInterval(readErrors, ERRORS_POLL_MS));
    readErrors();
  }

  return { draw, markStale, dispose() { for (const t of timers) clearInterval(t); } };
}
