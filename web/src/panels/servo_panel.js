// The servo panel, for com.robotraconteur.servo.Servo (one or more axes): the servo_state wire live (mode
// and flags by name, per axis the position, velocity, effort and command in the units of servo_info,
// a bar between position_min and position_max), servo_info, and for an operator Halt, the mode switch
// and hold-to-run jog per axis: while a − / + button is held the panel streams a ServoCommand on the
// velocity_command wire every 50 ms (the axis at the jog speed's share of its velocity_max, the others
// 0; the mode set to velocity_command first); every way the hold ends calls halt() at once
// (hold/stream_hold.js). The gateway halts the servo itself when the stream goes silent (its standard
// servo rules, docs/security.md "Motion safety"). A servo without a servo_state wire of the standard
// layout gets one line saying so and the generic member view below.

import { h, errorText } from "../dom.js";
import { describeMember } from "../views/context.js";
import { allows } from "../robot/access.js";
import { formatFlags, flagNames, enumName } from "../std/enums.js";
import { isStale, STALE_MS } from "../robot/status.js";
import { streamHold, holdMarks } from "../hold/stream_hold.js";
import { errorLine, whenAccess } from "./panel_parts.js";
import { servoAxisRows, axisCount, jogVelocities, servoCommand } from "../servo/servo_state.js";

const SV = "com.robotraconteur.servo";
export const SERVO = `${SV}.Servo`;

export function createServoPanel(parent, ctx) {
  const { obj, view } = ctx;
  const member = (name, kind) => (obj.$members || []).find((m) => m.name === name && m.kind === kind) || null;
  const enumValues = (name) => view?.outline?.types?.get(name)?.values ?? [];
  const J = "com.robotraconteur.robotics.joints";
  const enums = { flag: enumValues(`${SV}.ServoStateFlags`), mode: enumValues(`${SV}.ServoMode`), cap: enumValues(`${SV}.ServoCapabilities`),
    type: enumValues(`${SV}.ServoTypeCode`), position: enumValues(`${J}.JointPositionUnits`), effort: enumValues(`${J}.JointEffortUnits`) };
  let disposed = false;
  const alive = () => !disposed;
  const errors = errorLine("servo-error", alive);
  const staleBadge = h("span", { class: "badge robot-stale", dataset: { state: "closed" }, text: "stale", hidden: true });
  const rows = h("dl", { class: "robot-state-rows servo-state-rows" });
  const axes = h("table", { class: "robot-joints servo-axes" });
  const controls = h("div", { class: "camera-controls servo-controls" });
  const infoRows = h("dl", { class: "camera-info-rows servo-info" });
  const el = h("section", { class: "panel servo-panel", dataset: { panel: "servo", hold: "off" } },
    h("h3", {}, "Servo ", staleBadge), controls, errors.el, rows, axes, infoRows);
  parent.append(el);

  const stateWire = member("servo_state", "wire");
  const stateType = stateWire && !stateWire.writeonly ? describeMember(view, obj, stateWire)?.type : null;
  const fields = new Set((stateType?.fields || []).map((f) => f.name));
  if (stateType?.qualified !== `${SV}.ServoState` || !["servo_state_flags", "mode", "position"].every((f) => fields.has(f))) {
    el.dataset.fallback = "true";
    rows.replaceChildren(h("span", { class: "hint", text: "this servo has no servo_state wire of the standard ServoState type: its members are shown below" }));
    return { el, dispose() { el.remove(); } };
  }

  let info = null, state = null, lastMs = 0, frame = 0, seqno = 0, jogButtons = [], canJog = false;
  const speed = h("input", { type: "range", name: "servo-speed", min: "0.05", max: "1", step: "0.05", value: "0.25", "aria-label": "jog speed" });
  const fresh = () => !!state && !isStale(lastMs, Date.now());

  function drawAxes() {
    const list = servoAxisRows(state, info, enums);
    if (axes.tBodies[0]?.rows.length !== list.length) {
      if (hold?.active) hold.release("table rebuilt");
      hold?.forgetButtons(jogButtons);
      jogButtons = [];
      axes.replaceChildren(h("thead", {}, h("tr", {}, ...["axis", "position", "limits", "velocity", "effort", "command", canJog ? "jog" : ""].map((t) => h("th", { text: t })))),
        h("tbody", {}, ...list.map((r) => h("tr", { dataset: { axis: String(r.axis) } }, h("td", { text: `axis ${r.axis}` }), h("td", { class: "servo-position" }),
          h("td", {}, h("span", { class: "limit-bar" }, h("span", { class: "limit-mark" }))), h("td", { class: "servo-velocity" }), h("td", { class: "servo-effort" }),
          h("td", { class: "servo-command" }), h("td", {}, ...(canJog ? [-1, 1].map((d) => jogButton(r.axis, d)) : []))))));
    }
    Array.from(axes.tBodies[0].rows).forEach((tr, i) => {
      const r = list[i];
      tr.cells[1].textContent = r.position;
      tr.cells[3].textContent = r.velocity;
      tr.cells[4].textContent = r.effort;
      tr.cells[5].textContent = r.command;
      const [lo, hi] = r.limits, p = Number(state?.position?.[i]);
      const bar = tr.cells[2].firstChild;
      bar.hidden = !(lo !== null && hi !== null && hi > lo && Number.isFinite(p));
      if (!bar.hidden) bar.firstChild.style.left = `${(Math.max(0, Math.min(1, (p - lo) / (hi - lo))) * 100).toFixed(1)}%`;
    });
  }
  function draw() {
    frame = 0;
    if (disposed || !state) return;
    const mode = enumName(enums.mode, state.mode) ?? String(state.mode);
    const flags = formatFlags(enums.flag, state.servo_state_flags ?? 0);
    rows.replaceChildren(h("dt", { text: "mode" }), h("dd", { dataset: { row: "mode" }, text: mode }),
      h("dt", { text: "flags" }), h("dd", { dataset: { row: "servo_state_flags" }, text: flags }));
    el.dataset.mode = mode;
    el.dataset.flags = flags;
    drawAxes();
    refresh();
  }
  function refresh() {
    const on = fresh();
    staleBadge.hidden = !state || on;
    for (const b of jogButtons) { b.disabled = !on; b.title = on ? "" : "no fresh servo_state"; }
    if (!on && hold?.active) hold.release("stale");
  }
  const staleTimer = setInterval(refresh, STALE_MS / 2);
  const follow = ctx.live.followWire(stateWire.name, {
    onValue: (v) => { state = v; lastMs = Date.now(); if (!frame) frame = requestAnimationFrame(draw); },
    onError: (e) => { errors.onMemberError(stateWire.name)(e); if (e) hold?.release("servo_state closed"); },
  });

  // ---- the jog: velocity_command streamed while held, halt() when the hold ends ----
  let command = null, hold = null;
  const velocityMode = enums.mode.find((m) => m.name === "velocity_command")?.value;
  function jogButton(axis, dir) {
    const b = h("button", { type: "button", class: "small jog", text: dir > 0 ? "+" : "−", dataset: { axis: String(axis), dir: String(dir) } });
    jogButtons.push(hold.button(b, () => jogVelocities(info, axis, dir, Number(speed.value), axisCount(info, state))));
    return b;
  }
  function buildJog(access) {
    const caps = new Set(flagNames(enums.cap, info?.capabilities ?? 0));
    canJog = caps.has("velocity_command") && !!member("velocity_command", "wire") && allows(access, "velocity_command", "write")
      && !!member("halt", "function") && allows(access, "halt", "call") && velocityMode !== undefined;
    if (!canJog) return;
    command = ctx.live.followWire("velocity_command", { onValue: () => {}, onError: errors.onMemberError("velocity_command") });
    const mayMode = !!member("mode", "property") && allows(access, "mode", "write");
    hold = streamHold({
      client: obj.$client,
      send: (v) => command.setOutValue(servoCommand(++seqno, state?.seqno ?? 0, v)),
      stopDevice: () => obj.halt(),
      prepare: async () => {
        if (state && Number(state.mode) === velocityMode) return true;
        if (!mayMode) { errors.show("jog: set the mode to velocity_command first"); return false; }
        try {
          await obj.mode.set(velocityMode);
          return true;
        } catch (e) {
          errors.show(`mode: ${errorText(e)}`);
          return false;
        }
      },
      ...holdMarks(el, () => errors.show(null)),
      onError: (e, what) => { if (!disposed) errors.show(`${what === "stop" ? "halt" : what === "send" ? "velocity_command" : "jog"}: ${errorText(e)}`); },
    });
  }

  const infoMember = member("servo_info", "property");
  const infoRead = infoMember ? obj.servo_info.get().then((i) => {
    info = i;
    if (disposed || !i) return;
    const list = [["servo_type", "type", enumName(enums.type, i.servo_type) ?? String(i.servo_type)],
      ["capabilities", "capabilities", flagNames(enums.cap, i.capabilities ?? 0).join(" | ") || "none"],
      ["axis_count", "axes", String(i.axis_count)]];
    const range = (lo, hi) => Array.from(lo ?? [], (v, k) => `${v} … ${hi?.[k]}`).join(", ");
    if (i.velocity_max?.length) list.push(["velocity", "velocity", range(i.velocity_min, i.velocity_max)]);
    if (i.position_max?.length) list.push(["position", "position", range(i.position_min, i.position_max)]);
    infoRows.replaceChildren(...list.flatMap(([k, l, t]) => [h("dt", { text: l }), h("dd", { dataset: { row: k }, text: t })]));
  }, (e) => errors.show(`servo_info: ${errorText(e)}`)) : Promise.resolve();

  whenAccess(ctx, el, infoRead, alive, (access) => {
    if (member("halt", "function") && allows(access, "halt", "call")) {
      controls.append(h("button", { type: "button", class: "small", text: "Halt", dataset: { action: "halt" }, onclick: async () => {
        hold?.release("halt");
        try { await obj.halt(); errors.show(null); } catch (e) { errors.show(`halt: ${errorText(e)}`); }
      } }));
    }
    if (member("mode", "property") && allows(access, "mode", "write")) {
      const caps = new Set(flagNames(enums.cap, info?.capabilities ?? 0));
      const offered = enums.mode.filter((m) => m.name === "halt" || caps.has(m.name));
      const select = h("select", { name: "servo-mode", "aria-label": "mode" }, h("option", { value: "", text: "set mode…" }),
        ...offered.map((m) => h("option", { value: String(m.value), text: m.name })));
      select.addEventListener("change", async () => {
        if (select.value === "") return;
        try { await obj.mode.set(Number(select.value)); errors.show(null); } catch (e) { errors.show(`mode: ${errorText(e)}`); }
        select.value = "";
      });
      controls.append(select);
    }
    buildJog(access);
    if (canJog) controls.append(h("label", {}, " jog speed ", speed), h("span", { class: "hint", text: " hold − / + (velocity_command; halt() on release)" }));
    axes.replaceChildren();  // rebuilt with the jog column
    if (state) draw();
    el.dataset.ready = "true";
  }, (text) => { errors.show(text); el.dataset.ready = "true"; });

  return {
    el,
    dispose() {
      disposed = true;
      hold?.dispose();
      command?.dispose();
      follow.dispose();
      clearInterval(staleTimer);
      if (frame) cancelAnimationFrame(frame);
      el.remove();
    },
  };
}

export const servoPanel = { name: "servo", order: 20, types: [SERVO], create: createServoPanel };
