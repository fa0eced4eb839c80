// Press-and-hold for jog controls: a button jogs from pointerdown until the pointer lets go of it in
// any way (pointerup, pointercancel, lost pointer capture), and keyboard shortcuts jog from keydown
// to keyup. The window and tab events that end every hold (blur, hidden tab, page hide) are the
// panel's (robot_panel.js).

/**
 * Makes `button` a hold control: `press()` on pointerdown (primary button only, the pointer captured
 * so a release outside the button still counts), `release(reason)` on pointerup, pointercancel and
 * lostpointercapture. Returns a function removing the listeners.
 */
export function holdButton(button, press, release) {
  const down = (ev) => {
    if (ev.button !== 0 || button.disabled) return;
    ev.preventDefault();
    try { button.setPointerCapture(ev.pointerId); } catch { /* synthetic pointer: no capture */ }
    button.classList.add("held");
    press();
  };
  const up = (reason) => () => { button.classList.remove("held"); release(reason); };
  const handlers = [["pointerdown", down], ["pointerup", up("release")], ["pointercancel", up("pointercancel")],
    ["lostpointercapture", up("lostpointercapture")], ["contextmenu", (ev) => ev.preventDefault()]];
  for (const [type, fn] of handlers) button.addEventListener(type, fn);
  return () => { for (const [type, fn] of handlers) button.removeEventListener(type, fn); };
}

// Joint i (0-based) jogs + with PLUS_KEYS[i] and − with MINUS_KEYS[i]: the two rows of a keyboard.
const PLUS_KEYS = "qwertyu";
const MINUS_KEYS = "asdfghj";

/**
 * The joint jog of keyboard key `key` (KeyboardEvent.key): { joint, direction } or null. Q/A jog joint
 * 1 +/−, W/S joint 2, E/D joint 3, R/F 4, T/G 5, Y/H 6, U/J 7 (only joints the robot has).
 */
export function jogKey(key, jointCount) {
  const k = String(key).toLowerCase();
  let i = PLUS_KEYS.indexOf(k);
  if (i >= 0 && i < jointCount && k.length === 1) return { joint: i, direction: 1 };
  i = MINUS_KEYS.indexOf(k);
  if (i >= 0 && i < jointCount && k.length === 1) return { joint: i, direction: -1 };
  return null;
}

/** The shortcut keys of joint `i` as "Q/A", or "" beyond the seventh joint. */
export function jogKeysText(i) {
  return i < PLUS_KEYS.length ? `${PLUS_KEYS[i].toUpperCase()}/${MINUS_KEYS[i].toUpperCase()}` : "";
}
