// Hold-to-run over a command stream (a servo's velocity_command wire, an actuator's actuator_command):
// while held, the command is sent on the wire connection at once and every 50 ms (robot/jog_repeater.js);
// when the hold ends in any way (hold/hold_to_run.js) the sending stops and the device's stop is called
// at once (halt(), or the mode set to halt). A page that cannot send its stop is covered by the gateway:
// it stops a device whose command stream goes silent for its bound (server/gateway/motion_rules.hpp).

import { JogRepeater } from "../robot/jog_repeater.js";
import { HoldToRun } from "./hold_to_run.js";

/**
 * A HoldToRun streaming commands. `send(command)` sends one packet (throws when the wire is not
 * connected: that ends the hold); `stopDevice()` returns a promise (its failure goes to onError(e,
 * "stop")); `prepare` (optional) runs before each hold (e.g. the mode set to velocity_command). The rest
 * as HoldToRun's options; `timers` for tests.
 */
export function streamHold({ send, stopDevice, prepare = null, onStart, onStop = () => {}, onError = () => {}, client, win, doc, timers }) {
  let hold = null;
  const repeater = new JogRepeater({
    send,
    onError: (e) => onError(e, "send"),
    onStop: (reason) => {
      hold.stopped(reason);
      if (reason === "replaced") return;
      Promise.resolve().then(stopDevice).catch((e) => onError(e, "stop"));
    },
    timers,
  });
  hold = new HoldToRun({ motion: repeater, prepare, onStart, onStop, onError: (e) => onError(e, "command"), client, win, doc });
  return hold;
}

/**
 * onStart / onStop of a panel's hold that mark the panel element: data-hold "on" / "off", data-holds
 * counting the holds started (what tests wait for), data-hold-stop the reason the last one ended;
 * `clearError()` on each start.
 */
export function holdMarks(el, clearError = () => {}) {
  return {
    onStart: () => {
      clearError();
      el.dataset.hold = "on";
      el.dataset.holds = String(Number(el.dataset.holds ?? 0) + 1);
    },
    onStop: (reason) => { el.dataset.hold = "off"; el.dataset.holdStop = reason; },
  };
}
