// The robot panel's "move to" form (panels/robot_panel.js): a target for each joint in display units
// (degrees for revolute joints), "Current" fills in the robot's position, and the move is one
// jog_freespace call at a fraction of each joint's reduced velocity limit.

import { h, errorText } from "../dom.js";
import { toDisplay, fromDisplay, displayUnit } from "../robot/joints.js";

/** Fills `form` for the panel's `robot` when `show`, else empties and hides it. */
export function buildMoveForm(robot, form, show) {
  form.hidden = !show;
  if (!show) { form.replaceChildren(); return; }
  const { obj, model } = robot;
  const inputs = model.map((j) => h("input", { type: "number", step: "any", required: true, name: j.name, "aria-label": `${j.name} (${displayUnit(j.units)})` }));
  const fraction = h("input", { type: "number", min: "1", max: "100", step: "1", value: "10", name: "max-velocity" });
  const fill = h("button", { type: "button", class: "small", text: "Current", onclick: () => {
    const q = robot.state?.joint_position;
    if (q) inputs.forEach((inp, i) => { inp.value = String(Number(toDisplay(Number(q[i]), model[i].units).toFixed(4))); });
  } });
  const go = h("button", { type: "submit", class: "small", text: "Move to", dataset: { action: "jog_freespace" } });
  form.replaceChildren(h("span", { class: "state-label", text: "move to" }),
    ...model.map((j, i) => h("label", {}, `${j.name} `, inputs[i], ` ${displayUnit(j.units)}`)),
    h("label", {}, "max velocity ", fraction, " % of limit"), fill, go);
  form.onsubmit = async (ev) => {
    ev.preventDefault();
    const q = inputs.map((inp, i) => fromDisplay(Number(inp.value), model[i].units));
    const f = Number(fraction.value) / 100;
    if (q.some((x) => !Number.isFinite(x)) || !(f > 0 && f <= 1)) { robot.showError("move to: every joint needs a number, max velocity 1..100 %"); return; }
    go.disabled = true;
    try {
      // wait true: the call lasts as long as the move, so the gateway's hold on the robot's motion (one
      // client at a time, docs/security.md "Motion safety") ends with it, not with this page.
      await obj.jog_freespace(Float64Array.from(q), Float64Array.from(model, (j) => f * j.reducedVelocity), true);
      if (!robot.disposed) robot.showError(null);
    } catch (e) {
      if (!robot.disposed) robot.showError(`jog_freespace: ${errorText(e)}`);
    } finally {
      go.disabled = false;
    }
  };
}
