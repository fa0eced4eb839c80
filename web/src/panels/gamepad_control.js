// "Move with a gamepad": the robot and tool panels' gamepad input (hold/gamepad.js) feeding the
// panel's hold-to-run helper (hold/hold_to_run.js), so a gamepad's stick or button holds a motion
// exactly as a held button does and every way a hold ends applies to it too. Off until the operator
// ticks it; then the gamepad must be seen at rest first. Only where the browser has the Gamepad API
// (navigator.getGamepads: a secure context, i.e. https:// or localhost).

import { h } from "../dom.js";
import { GamepadFollower, inputName } from "../hold/gamepad.js";

/** True when this browser offers the Gamepad API. */
export function hasGamepadApi() {
  return typeof globalThis.navigator?.getGamepads === "function";
}

/**
 * The checkbox and status line of a panel's gamepad input. `bindings()` gives the bindings now;
 * `press(binding)` starts its hold through the panel's HoldToRun (false when the panel may not move
 * now); the hold ends through `hold.release(reason)`. Returns { el, dispose() }.
 */
export function createGamepadControl(hold, { bindings, press, what = "jog" }) {
  const check = h("input", { type: "checkbox", name: "gamepad" });
  const status = h("output", { class: "gamepad-status" });
  const keys = h("span", { class: "hint gamepad-keys" });
  const el = h("div", { class: "gamepad-control", dataset: { gamepad: "off" } },
    h("label", {}, check, ` ${what} with a gamepad`), " ", status, " ", keys);
  const follower = new GamepadFollower({
    bindings,
    onHold: (b) => press(b),
    onRelease: (reason) => hold.release(reason),
    onStatus: ({ state, pad, binding }) => {
      el.dataset.gamepad = state;
      const name = pad?.id ? pad.id.replace(/\s*\(.*$/, "") || "gamepad" : "gamepad";
      status.textContent = state === "none" ? "no gamepad: connect one and press a button on it"
        : state === "unarmed" ? `${name}: let go of the sticks and buttons first`
        : state === "holding" ? `${name}: ${binding.id} (${inputName(binding)})`
        : `${name}: ready`;
    },
  });
  const offFollow = hold.follow(follower);
  check.addEventListener("change", () => {
    if (check.checked) {
      keys.textContent = bindings().map((b) => `${inputName(b)}: ${b.id}`).join(", ");
      follower.start();
    } else {
      follower.stop();
      el.dataset.gamepad = "off";
      status.textContent = "";
      keys.textContent = "";
    }
  });
  return {
    el,
    get follower() { return follower; },
    dispose() { follower.stop(); offFollow(); },
  };
}
