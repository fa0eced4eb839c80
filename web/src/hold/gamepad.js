// A gamepad held by the browser (the Gamepad API) as a hold-to-run input (hold/hold_to_run.js): a
// stick pushed past half its travel, or a bound button pressed, holds the motion bound to it; the
// stick back near the centre, the button let go or the gamepad lost (disconnected, gone from
// navigator.getGamepads()) releases it. Safe by construction:
//   * the gamepad is armed only once every bound stick and button has been seen at rest (after the
//     page starts following it, after it reconnects, and after any hold that ended elsewhere: a blur,
//     a refused call, stale state), so a stick stuck off-centre or still held never starts a motion;
//   * one binding at a time (the most deflected); moving to another binding replaces the motion;
//   * the page reads the gamepad every 20 ms; a gamepad that stops reporting is released at once.
// Sticks and buttons are read in the browser's "standard" mapping (w3c Gamepad, "Remapping").

/** Deflection (0..1) past which a stick or analog button holds its binding. */
export const HOLD_AT = 0.5;
/** Deflection (0..1) under which a stick or button counts as at rest (arming). */
export const REST_BELOW = 0.2;
/** Milliseconds between two reads of the gamepad. */
export const GAMEPAD_PERIOD_MS = 20;

/** Names of the standard mapping's inputs, for hints ("left stick →", "A"). */
const AXIS_NAMES = ["left stick x", "left stick y", "right stick x", "right stick y"];
const BUTTON_NAMES = ["A", "B", "X", "Y", "LB", "RB", "LT", "RT", "back", "start", "left stick press", "right stick press",
  "d-pad up", "d-pad down", "d-pad left", "d-pad right", "guide"];

/**
 * @typedef {object} GamepadBinding
 * @property {string} id  what it holds ("joint 1 +", "close")
 * @property {number} [axis]  stick axis index (standard mapping)
 * @property {number} [sign]  +1: the axis's positive direction holds it, -1: the negative
 * @property {number} [button]  button index (standard mapping)
 * @property {any} [command]  what the panel makes of it
 */

/** How far `binding` is pushed on `pad` (0..1). */
export function deflection(pad, binding) {
  if (Number.isInteger(binding.axis)) {
    const v = Number(pad?.axes?.[binding.axis]);
    return Number.isFinite(v) ? Math.max(0, Math.min(1, v * (binding.sign ?? 1))) : 0;
  }
  const b = pad?.buttons?.[binding.button];
  if (!b) return 0;
  if (typeof b === "number") return Math.max(0, Math.min(1, b));
  const v = Number(b.value);
  return b.pressed ? Math.max(1e-9, Number.isFinite(v) && v > 0 ? Math.min(1, v) : 1) : Math.max(0, Math.min(1, Number.isFinite(v) ? v : 0));
}

/** The binding held on `pad`: the most deflected at HOLD_AT or more (a pressed digital button counts fully); null for none. */
export function heldBinding(pad, bindings) {
  let best = null, most = 0;
  for (const b of bindings) {
    const d = deflection(pad, b);
    const pressed = !Number.isInteger(b.axis) && pad?.buttons?.[b.button]?.pressed;
    const amount = pressed ? Math.max(d, 1) : d;
    if (amount >= HOLD_AT && amount > most) { best = b; most = amount; }
  }
  return best;
}

/** True when every bound stick and button of `pad` is at rest (under REST_BELOW, no button pressed). */
export function atRest(pad, bindings) {
  return bindings.every((b) => {
    if (!Number.isInteger(b.axis) && pad?.buttons?.[b.button]?.pressed) return false;
    return deflection(pad, b) < REST_BELOW;
  });
}

/** "left stick y ↑", "A": the input of a binding as a person names it. */
export function inputName(binding) {
  if (Number.isInteger(binding.axis)) {
    const name = AXIS_NAMES[binding.axis] ?? `axis ${binding.axis}`;
    const up = binding.axis % 2 === 1;  // y axes: negative is up in the standard mapping
    const arrow = up ? (binding.sign < 0 ? "↑" : "↓") : (binding.sign < 0 ? "←" : "→");
    return `${name} ${arrow}`;
  }
  return BUTTON_NAMES[binding.button] ?? `button ${binding.button}`;
}

/**
 * The robot's joint jogs on a standard gamepad: left stick x joint 1, left stick y joint 2 (up +),
 * right stick y joint 3 (up +), right stick x joint 4, d-pad up/down joint 5, d-pad right/left joint 6,
 * RB/LB joint 7; only the joints the robot has. `command(i, dir)` makes each binding's command.
 */
export function jointBindings(jointCount, command = () => null) {
  const inputs = [
    [{ axis: 0, sign: 1 }, { axis: 0, sign: -1 }],
    [{ axis: 1, sign: -1 }, { axis: 1, sign: 1 }],
    [{ axis: 3, sign: -1 }, { axis: 3, sign: 1 }],
    [{ axis: 2, sign: 1 }, { axis: 2, sign: -1 }],
    [{ button: 12 }, { button: 13 }],
    [{ button: 15 }, { button: 14 }],
    [{ button: 5 }, { button: 4 }],
  ];
  const out = [];
  for (let i = 0; i < Math.min(jointCount, inputs.length); i++) {
    const [plus, minus] = inputs[i];
    out.push({ ...plus, id: `joint ${i + 1} +`, joint: i, direction: 1, command: command(i, 1) });
    out.push({ ...minus, id: `joint ${i + 1} −`, joint: i, direction: -1, command: command(i, -1) });
  }
  return out;
}

/**
 * Follows one gamepad for a HoldToRun: `onHold(binding)` when a binding becomes held (the panel
 * presses its command; false when it may not move now), `onRelease(reason)` when it is let go ("gamepad released") or the gamepad is
 * lost ("gamepad lost"). `onStatus({ state, pad, binding })` after each change: state "none" (no
 * gamepad), "unarmed" (waiting for the sticks at rest), "armed", "holding". The HoldToRun tells it of
 * holds that ended elsewhere (holdEnded): it then waits for rest again.
 */
export class GamepadFollower {
  /**
   * @param {object} o
   * @param {() => GamepadBinding[]} o.bindings  the bindings now (the joints can change)
   * @param {() => ArrayLike<Gamepad|null>} [o.getGamepads]  navigator.getGamepads
   * @param {EventTarget} [o.win]  window: its gamepaddisconnected releases at once
   */
  constructor({ bindings, onHold, onRelease, onStatus = () => {}, getGamepads = () => globalThis.navigator?.getGamepads?.() ?? [],
    win = globalThis.window, timers = globalThis, periodMs = GAMEPAD_PERIOD_MS }) {
    Object.assign(this, { bindings, onHold, onRelease, onStatus, getGamepads, win, timers, periodMs });
    this.timer = null;
    this.padIndex = null;  // the gamepad followed (the first seen)
    this.armed = false;
    this.current = null;   // the binding held
    this.state = "none";
    this.onDisconnected = (ev) => { if (ev?.gamepad?.index === this.padIndex) this.lost(); };
  }

  get running() { return this.timer !== null; }

  start() {
    if (this.running) return;
    this.armed = false;
    this.win?.addEventListener?.("gamepaddisconnected", this.onDisconnected);
    this.timer = this.timers.setInterval(() => this.poll(), this.periodMs);
    this.poll();
  }

  stop() {
    if (!this.running) return;
    this.timers.clearInterval(this.timer);
    this.timer = null;
    this.win?.removeEventListener?.("gamepaddisconnected", this.onDisconnected);
    this.releaseHeld("gamepad off");
    this.padIndex = null;
    this.setState("none", null);
  }

  /** The HoldToRun ended a hold (any input, any reason): wait for rest before the next. */
  holdEnded(reason, source) {
    if (source === "gamepad" && String(reason).startsWith("gamepad")) return;  // its own release
    this.current = null;
    this.armed = false;
    if (this.running && this.pad) this.setState("unarmed", this.pad);
  }

  /** The pad followed in `pads`: the one seen before, else the first connected. */
  pick(pads) {
    const list = Array.from(pads ?? []).filter((p) => p && p.connected !== false);
    if (this.padIndex !== null) return list.find((p) => p.index === this.padIndex) ?? null;
    const p = list[0] ?? null;
    if (p) this.padIndex = p.index;
    return p;
  }

  poll() {
    if (!this.running) return;
    let pads;
    try { pads = this.getGamepads(); } catch { pads = []; }
    const pad = this.pick(pads);
    this.pad = pad;
    if (!pad) { if (this.padIndex !== null || this.state !== "none") this.lost(); return; }
    const bindings = this.bindings();
    if (!this.armed) {
      if (atRest(pad, bindings)) { this.armed = true; this.setState("armed", pad); }
      else if (this.state !== "unarmed") this.setState("unarmed", pad);
      return;
    }
    // a held binding stays held until it drops back near rest (no flicker around HOLD_AT)
    if (this.current && deflection(pad, this.current) >= REST_BELOW && bindings.some((b) => b.id === this.current.id)) {
      const other = heldBinding(pad, bindings.filter((b) => b.id !== this.current.id));
      if (!other || deflection(pad, other) <= deflection(pad, this.current)) return;
      this.hold(other, pad);
      return;
    }
    const next = heldBinding(pad, bindings);
    if (this.current && !next) { this.releaseHeld("gamepad released"); this.setState("armed", pad); return; }
    if (next && next.id !== this.current?.id) this.hold(next, pad);
  }

  /** Holds `binding`; the panel's onHold returning false (it may not move now) disarms until rest. */
  hold(binding, pad) {
    this.current = binding;
    this.setState("holding", pad, binding);
    if (this.onHold(binding) === false) {
      this.current = null;
      this.armed = false;
      this.setState("unarmed", pad);
    }
  }

  lost() {
    this.releaseHeld("gamepad lost");
    this.padIndex = null;
    this.armed = false;
    this.pad = null;
    this.setState("none", null);
  }

  releaseHeld(reason) {
    if (!this.current) return;
    this.current = null;
    this.onRelease(reason);
  }

  setState(state, pad, binding = null) {
    this.state = state;
    this.onStatus({ state, pad, binding });
  }
}
