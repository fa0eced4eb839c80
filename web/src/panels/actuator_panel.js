// The actuator panel, for com.robotraconteur.actuator.Actuator (valves, conveyors, heaters, cylinders):
// the actuator_state wire live (flags by name, the commands in actuator_info's command_units), the mode
// (actuator_mode, read every second: a property without a wire), actuator_info, and for an operator
// the mode switch and "Run (hold)": while held the panel streams the value entered on the
// actuator_command wire every 50 ms (the mode set to normal first when it is halt); every way the hold
// ends sets actuator_mode to halt at once, the standard actuator's stop (hold/stream_hold.js). The
// gateway does the same when the stream goes silent (docs/security.md "Motion safety"). An actuator
// without an actuator_state wire of the standard layout gets one line and the generic view below.

import { h, errorText } from "../dom.js";
import { describeMember } from "../views/context.js";
import { allows } from "../robot/access.js";
import { formatFlags, enumName } from "../std/enums.js";
import { siUnitText } from "../std/units.js";
import { streamHold, holdMarks } from "../hold/stream_hold.js";
import { errorLine, whenAccess } from "./panel_parts.js";
import { actuatorRows, actuatorCommand } from "../servo/servo_state.js";

const A = "com.robotraconteur.actuator";
export const ACTUATOR = `${A}.Actuator`;
const POLL_MS = 1000;

export function createActuatorPanel(parent, ctx) {
  const { obj, view } = ctx;
  const member = (name, kind) => (obj.$members || []).find((m) => m.name === name && m.kind === kind) || null;
  const enumValues = (name) => view?.outline?.types?.get(name)?.values ?? [];
  const enums = { flag: enumValues(`${A}.ActuatorStateFlags`), mode: enumValues(`${A}.ActuatorMode`), type: enumValues(`${A}.ActuatorTypeCode`) };
  let disposed = false;
  const alive = () => !disposed;
  const errors = errorLine("actuator-error", alive);
  const rows = h("dl", { class: "robot-state-rows actuator-state-rows" });
  const controls = h("div", { class: "camera-controls actuator-controls" });
  const infoRows = h("dl", { class: "camera-info-rows actuator-info" });
  const el = h("section", { class: "panel actuator-panel", dataset: { panel: "actuator", hold: "off" } },
    h("h3", { text: "Actuator" }), controls, errors.el, rows, infoRows);
  parent.append(el);

  const stateWire = member("actuator_state", "wire");
  const stateType = stateWire && !stateWire.writeonly ? describeMember(view, obj, stateWire)?.type : null;
  if (stateType?.qualified !== `${A}.ActuatorState` || !stateType.fields?.some((f) => f.name === "actuator_command")) {
    el.dataset.fallback = "true";
    rows.replaceChildren(h("span", { class: "hint", text: "this actuator has no actuator_state wire of the standard ActuatorState type: its members are shown below" }));
    return { el, dispose() { el.remove(); } };
  }

  let info = null, state = null, mode = null, frame = 0, hold = null, command = null;
  const modeValue = (name) => enums.mode.find((m) => m.name === name)?.value;
  function draw() {
    frame = 0;
    if (disposed) return;
    const list = [["actuator_mode", "mode", mode === null ? "" : enumName(enums.mode, mode) ?? String(mode)]];
    if (state) {
      list.push(["actuator_state_flags", "flags", formatFlags(enums.flag, state.actuator_state_flags ?? 0)]);
      for (const r of actuatorRows(state, info)) list.push([r.key, r.label, r.text]);
    }
    rows.replaceChildren(...list.flatMap(([k, l, t]) => [h("dt", { text: l }), h("dd", { dataset: { row: k }, text: t })]));
    el.dataset.mode = list[0][2];
  }
  const schedule = () => { if (!frame) frame = requestAnimationFrame(draw); };
  const follow = ctx.live.followWire(stateWire.name, {
    onValue: (v) => { state = v; schedule(); },
    onError: (e) => { errors.onMemberError(stateWire.name)(e); if (e) hold?.release("actuator_state closed"); },
  });
  const hasMode = !!member("actuator_mode", "property");
  const readMode = () => (hasMode ? obj.actuator_mode.get().then((m) => { mode = Number(m); schedule(); }, () => {}) : Promise.resolve());
  readMode();
  const poll = setInterval(readMode, POLL_MS);

  const infoMember = member("actuator_info", "property");
  const infoRead = infoMember ? obj.actuator_info.get().then((i) => {
    info = i;
    if (disposed || !i) return;
    const units = Array.from(i.command_units ?? [], siUnitText).filter(Boolean).join(", ");
    const list = [["actuator_type", "type", enumName(enums.type, i.actuator_type) ?? String(i.actuator_type)],
      ["command_units", "command units", units || "none"], ["analog_output", "analog", i.analog_output ? "yes" : "no"]];
    infoRows.replaceChildren(...list.flatMap(([k, l, t]) => [h("dt", { text: l }), h("dd", { dataset: { row: k }, text: t })]));
    schedule();
  }, (e) => errors.show(`actuator_info: ${errorText(e)}`)) : Promise.resolve();

  whenAccess(ctx, el, infoRead, alive, (access) => {
    const mayMode = hasMode && allows(access, "actuator_mode", "write");
    if (mayMode) {
      const select = h("select", { name: "actuator-mode", "aria-label": "mode" }, h("option", { value: "", text: "set mode…" }),
        ...enums.mode.filter((m) => m.value >= 0).map((m) => h("option", { value: String(m.value), text: m.name })));
      select.addEventListener("change", async () => {
        if (select.value === "") return;
        try { await obj.actuator_mode.set(Number(select.value)); errors.show(null); } catch (e) { errors.show(`actuator_mode: ${errorText(e)}`); }
        select.value = "";
        readMode();
      });
      controls.append(select);
    }
    // Run (hold) needs the command stream and the stop (the mode set to halt)
    if (member("actuator_command", "wire") && allows(access, "actuator_command", "write") && mayMode && modeValue("halt") !== undefined) {
      command = ctx.live.followWire("actuator_command", { onValue: () => {}, onError: errors.onMemberError("actuator_command") });
      const input = h("input", { type: "number", name: "actuator-command", step: "any", value: "0", "aria-label": "command" });
      hold = streamHold({
        client: obj.$client,
        send: (v) => command.setOutValue(v),
        stopDevice: async () => { await obj.actuator_mode.set(modeValue("halt")); await readMode(); },
        prepare: async () => {
          const m = enumName(enums.mode, await obj.actuator_mode.get());
          if (m === "normal" || m === "reduced_performance") return true;
          try {
            await obj.actuator_mode.set(modeValue("normal"));
            return true;
          } catch (e) {
            errors.show(`actuator_mode: ${errorText(e)}`);
            return false;
          }
        },
        ...holdMarks(el, () => errors.show(null)),
        onError: (e, what) => { if (!disposed) errors.show(`${what === "stop" ? "actuator_mode" : what === "send" ? "actuator_command" : "run"}: ${errorText(e)}`); },
      });
      const run = hold.button(h("button", { type: "button", class: "small jog", text: "Run (hold)", dataset: { action: "run" } }),
        () => actuatorCommand(input.value, state?.actuator_command?.length || 1));
      controls.append(h("label", {}, " command ", input), run,
        h("span", { class: "hint", text: " the actuator runs only while Run is held; release sets the mode to halt" }));
    }
    el.dataset.ready = "true";
  }, (text) => { errors.show(text); el.dataset.ready = "true"; });

  return {
    el,
    dispose() {
      disposed = true;
      hold?.dispose();
      command?.dispose();
      follow.dispose();
      clearInterval(poll);
      if (frame) cancelAnimationFrame(frame);
      el.remove();
    },
  };
}

export const actuatorPanel = { name: "actuator", order: 20, types: [ACTUATOR], create: createActuatorPanel };
