// The robot panel's joints table (panels/robot_panel.js): one row per joint of robot_info, named and
// bounded from it, with the position, a limit bar warning near a limit, velocity, effort and, when the
// user may jog, hold-to-jog − / + buttons (panels/robot_jog.js).

import { h } from "../dom.js";
import { jointRows } from "../robot/joints.js";

/** Fills `table` for the panel's `robot` and its `jog`; render(rebuild) draws the newest state. */
export function createJointsTable(robot, jog, table) {
  const buttons = jog.tableButtons;
  function render(rebuild) {
    const { model, state } = robot;
    const rows = jointRows(state ?? { joint_position: new Float64Array(model.length) }, model);
    const withJog = jog.shown;
    if (rebuild || table.tBodies[0]?.rows.length !== rows.length) {
      if (buttons.some((b) => b.classList.contains("held"))) jog.release("table rebuilt");
      jog.forget(buttons);
      table.replaceChildren(
        h("thead", {}, h("tr", {}, ...["joint", "position", "limits", "velocity", "effort", withJog ? "jog" : ""].map((t) => h("th", { text: t })))),
        h("tbody", {}, ...rows.map((r, i) => h("tr", { dataset: { joint: r.name } },
          h("td", { class: "joint-name", text: r.name }), h("td", { class: "joint-position" }),
          h("td", { class: "joint-limits" }, h("span", { class: "limit-bar" }, h("span", { class: "limit-mark" }))),
          h("td", { class: "joint-velocity" }), h("td", { class: "joint-effort" }),
          h("td", { class: "joint-jog" }, ...(withJog ? [jog.button(buttons, "−", { joint: r.name, dir: "-1" }, jog.jointCommand(i, -1)),
            jog.button(buttons, "+", { joint: r.name, dir: "1" }, jog.jointCommand(i, 1))] : []))))));
    }
    if (!state) return;
    Array.from(table.tBodies[0].rows).forEach((tr, i) => {
      const r = rows[i];
      tr.cells[1].textContent = r.text;
      const mark = tr.cells[2].firstChild.firstChild;
      tr.cells[2].firstChild.hidden = r.fraction === null;
      if (r.fraction !== null) mark.style.left = `${(r.fraction * 100).toFixed(1)}%`;
      tr.dataset.near = r.near ?? "";
      tr.cells[2].title = r.near ? `near the ${r.near} limit (${model[i].lower} … ${model[i].upper})` : "";
      tr.cells[3].textContent = r.velocity;
      tr.cells[4].textContent = r.effort;
    });
  }
  return { render };
}
