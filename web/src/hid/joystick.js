// The joystick panel's pure logic (panels/joystick_panel.js): com.robotraconteur.hid.joystick values as
// a person reads them. Axes are int16 (-32768 … 32767, full travel both ways), buttons uint8 (0
// released), hats JoystickHatState codes; a GamepadState's sticks and triggers are int16 too and its
// buttons a GamepadButtons flag word.

import { enumName, flagNames } from "../std/enums.js";

/** An int16 axis as a fraction of its travel, -1 … 1 (0 for anything that is no number). */
export function axisFraction(v) {
  const n = Number(v);
  if (!Number.isFinite(n)) return 0;
  return Math.max(-1, Math.min(1, n >= 0 ? n / 32767 : n / 32768));
}

/** "16384 (50%)": the raw axis value and its share of the travel. */
export function axisText(v) {
  const pct = Math.round(axisFraction(v) * 100);
  return `${Number(v)} (${Object.is(pct, -0) ? 0 : pct}%)`;
}

/** Indices of the pressed buttons of a JoystickState's `buttons`. */
export function pressedButtons(buttons) {
  return Array.from(buttons ?? []).flatMap((b, i) => (Number(b) !== 0 ? [i] : []));
}

/** A hat's JoystickHatState name ("hat_up"), or its number when the enum has none. */
export function hatText(hatEnum, v) {
  return enumName(hatEnum, v) ?? String(v);
}

/**
 * Rows [{ key, label, text }] of a GamepadState: the sticks as "(x%, y%)", the triggers in %, the
 * buttons by GamepadButtons name ("none" when none is pressed).
 */
export function gamepadRows(state, buttonEnum) {
  if (!state || typeof state !== "object") return [];
  const pct = (v) => `${Math.round(axisFraction(v) * 100)}%`.replace(/^-0%$/, "0%");
  const names = flagNames(buttonEnum, state.buttons ?? 0);
  return [
    { key: "left", label: "left stick", text: `(${pct(state.left_x)}, ${pct(state.left_y)})` },
    { key: "right", label: "right stick", text: `(${pct(state.right_x)}, ${pct(state.right_y)})` },
    { key: "triggers", label: "triggers", text: `left ${pct(state.trigger_left)}, right ${pct(state.trigger_right)}` },
    { key: "gamepad-buttons", label: "buttons", text: names.length ? names.map((n) => n.replace(/^button_/, "")).join(" | ") : "none" },
  ];
}

/** Rows [{ key, label, text }] of a JoystickInfo: id, counts, capabilities by name, USB ids as hex. */
export function joystickInfoRows(info, capEnum) {
  if (!info || typeof info !== "object") return [];
  const hex = (v) => Number(v).toString(16).padStart(4, "0");
  const rows = [];
  if (info.id !== undefined) rows.push({ key: "id", label: "id", text: String(info.id) });
  rows.push({ key: "counts", label: "inputs", text: `${info.axes_count ?? 0} axes, ${info.button_count ?? 0} buttons, ${info.hat_count ?? 0} hats` });
  if (info.joystick_capabilities !== undefined) {
    const caps = flagNames(capEnum, info.joystick_capabilities);
    rows.push({ key: "capabilities", label: "capabilities", text: caps.length ? caps.join(" | ") : "none" });
  }
  if (info.joystick_device_vendor !== undefined) {
    rows.push({ key: "usb", label: "USB id", text: `${hex(info.joystick_device_vendor)}:${hex(info.joystick_device_product ?? 0)} v${hex(info.joystick_device_version ?? 0)}` });
  }
  return rows;
}
