// The joystick panel, for com.robotraconteur.hid.joystick.Joystick: the joystick_state wire live (each
// axis as its raw int16 and share of travel with a bar, the pressed buttons lit, each hat by name), the
// gamepad_state wire when the device has it (sticks, triggers, buttons by name), joystick_info, and
// "Rumble" for an operator whose joystick can (capability rumble, the gateway letting the user call
// rumble). Newest value drawn at most once per animation frame. A device without a joystick_state wire
// of the standard layout gets one line saying so and the generic member view below.

import { h, errorText } from "../dom.js";
import { describeMember } from "../views/context.js";
import { allows } from "../robot/access.js";
import { axisFraction, axisText, pressedButtons, hatText, gamepadRows, joystickInfoRows } from "../hid/joystick.js";
import { errorLine, whenAccess } from "./panel_parts.js";
import { flagNames } from "../std/enums.js";

const J = "com.robotraconteur.hid.joystick";
export const JOYSTICK = `${J}.Joystick`;

export function createJoystickPanel(parent, ctx) {
  const { obj, view } = ctx;
  const member = (name, kind) => (obj.$members || []).find((m) => m.name === name && m.kind === kind) || null;
  const typed = (name, kind, typeName, fields) => {
    const m = member(name, kind);
    const t = m && !m.writeonly ? describeMember(view, obj, m)?.type : null;
    return t?.qualified === typeName && fields.every((f) => t.fields?.some((x) => x.name === f)) ? m : null;
  };
  const enumValues = (name) => view?.outline?.types?.get(name)?.values ?? [];
  let disposed = false;
  const alive = () => !disposed;
  const errors = errorLine("joystick-error", alive);
  const axesTable = h("table", { class: "robot-joints joystick-axes" });
  const buttonsRow = h("div", { class: "joystick-buttons" });
  const hatsRow = h("div", { class: "joystick-hats" });
  const padRows = h("dl", { class: "camera-info-rows joystick-gamepad", hidden: true });
  const infoRows = h("dl", { class: "camera-info-rows joystick-info" });
  const controls = h("div", { class: "camera-controls joystick-controls" });
  const el = h("section", { class: "panel joystick-panel", dataset: { panel: "joystick", samples: "0" } },
    h("h3", { text: "Joystick" }), errors.el, axesTable, buttonsRow, hatsRow, padRows, controls, infoRows);
  parent.append(el);

  const stateWire = typed("joystick_state", "wire", `${J}.JoystickState`, ["axes", "buttons"]);
  if (!stateWire) {
    el.dataset.fallback = "true";
    el.append(h("div", { class: "hint", text: "no joystick_state wire of the standard JoystickState type on this device: its members are shown below" }));
    return { el, dispose() { el.remove(); } };
  }
  const padWire = typed("gamepad_state", "wire", `${J}.GamepadState`, ["left_x", "left_y", "buttons"]);
  const enums = { hat: enumValues(`${J}.JoystickHatState`), button: enumValues(`${J}.GamepadButtons`), cap: enumValues(`${J}.JoystickCapabilities`) };
  let newest = null, newestPad = null, frame = 0, count = 0, info = null;

  function drawAxes(axes) {
    const list = Array.from(axes ?? []);
    if (axesTable.tBodies[0]?.rows.length !== list.length) {
      axesTable.replaceChildren(h("thead", {}, h("tr", {}, h("th", { text: "axis" }), h("th", { text: "value" }), h("th", { text: "" }))),
        h("tbody", {}, ...list.map((_, i) => h("tr", { dataset: { axis: String(i) } }, h("td", { text: `axis ${i}` }),
          h("td", { class: "joystick-axis-value" }), h("td", {}, h("span", { class: "limit-bar" }, h("span", { class: "limit-mark" })))))));
    }
    Array.from(axesTable.tBodies[0].rows).forEach((tr, i) => {
      tr.cells[1].textContent = axisText(list[i]);
      tr.cells[2].firstChild.firstChild.style.left = `${((axisFraction(list[i]) + 1) * 50).toFixed(1)}%`;
    });
  }
  function drawButtons(buttons) {
    const n = Math.max(Array.from(buttons ?? []).length, Number(info?.button_count ?? 0));
    const pressed = new Set(pressedButtons(buttons));
    if (buttonsRow.childElementCount !== n) {
      buttonsRow.replaceChildren(...Array.from({ length: n }, (_, i) => h("span", { class: "chip", text: String(i), dataset: { button: String(i) } })));
    }
    Array.from(buttonsRow.children).forEach((c, i) => { c.className = pressed.has(i) ? "chip chip-good" : "chip"; c.dataset.pressed = String(pressed.has(i)); });
    el.dataset.pressed = [...pressed].join(",");
  }
  function draw() {
    frame = 0;
    if (disposed) return;
    if (newest) {
      drawAxes(newest.axes);
      drawButtons(newest.buttons);
      const hats = Array.from(newest.hats ?? []);
      hatsRow.replaceChildren(...hats.map((v, i) => h("span", { class: "chip", dataset: { hat: String(i) }, text: `hat ${i}: ${hatText(enums.hat, v)}` })));
    }
    if (newestPad) {
      padRows.hidden = false;
      padRows.replaceChildren(...gamepadRows(newestPad, enums.button).flatMap((r) => [h("dt", { text: r.label }), h("dd", { dataset: { row: r.key }, text: r.text })]));
    }
    el.dataset.samples = String(count);
  }
  const schedule = () => { if (!frame) frame = requestAnimationFrame(draw); };
  const follows = [ctx.live.followWire(stateWire.name, {
    onValue: (v) => { newest = v; count++; schedule(); },
    onError: errors.onMemberError(stateWire.name),
  })];
  if (padWire) follows.push(ctx.live.followWire(padWire.name, { onValue: (v) => { newestPad = v; schedule(); }, onError: errors.onMemberError(padWire.name) }));

  const infoMember = typed("joystick_info", "property", `${J}.JoystickInfo`, ["axes_count", "button_count"]);
  const infoRead = infoMember ? obj.joystick_info.get().then((i) => {
    info = i;
    if (disposed) return;
    infoRows.replaceChildren(...joystickInfoRows(i, enums.cap).flatMap((r) => [h("dt", { text: r.label }), h("dd", { dataset: { row: r.key }, text: r.text })]));
  }, (e) => errors.show(`joystick_info: ${errorText(e)}`)) : Promise.resolve();

  // Rumble, for an operator whose joystick has the capability
  whenAccess(ctx, el, infoRead, alive, (access) => {
    const canRumble = member("rumble", "function") && allows(access, "rumble", "call")
      && (!info || flagNames(enums.cap, info.joystick_capabilities ?? 0).includes("rumble"));
    if (canRumble) {
      const intensity = h("input", { type: "range", name: "rumble-intensity", min: "0", max: "1", step: "0.1", value: "0.5", "aria-label": "rumble intensity" });
      const button = h("button", { type: "button", class: "small", dataset: { action: "rumble" }, text: "Rumble 0.5 s", onclick: async () => {
        button.disabled = true;
        try {
          await obj.rumble(Number(intensity.value), 0.5);
          errors.show(null);
        } catch (e) {
          errors.show(`rumble: ${errorText(e)}`);
        } finally {
          button.disabled = false;
        }
      } });
      controls.replaceChildren(h("label", {}, "intensity ", intensity), button);
    }
    el.dataset.ready = "true";
  }, (text) => { errors.show(text); el.dataset.ready = "true"; });

  return {
    el,
    dispose() { disposed = true; for (const f of follows) f.dispose(); if (frame) cancelAnimationFrame(frame); el.remove(); },
  };
}

export const joystickPanel = { name: "joystick", order: 20, types: [JOYSTICK], create: createJoystickPanel };
