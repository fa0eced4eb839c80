// Hold-to-run, shared by every panel whose controls move hardware (the robot's jog, the tool's
// motions, a gamepad driving either): a motion runs only while a control is held, and every way the
// page can lose the operator ends the hold. How a hold keeps the device moving and how it stops it is
// the panel's `motion`: the robot renews short jog timeouts while held (robot/jog_repeater.js), the
// tool calls halt() when the hold ends (tool/tool_state.js ToolHold). The gateway's motion rules
// (server/gateway/motion_*) are the real dead-man: they stop a device whose client went away.
//
// Ends a hold: the control let go (pointerup, pointercancel, lost capture: robot/hold.js holdButton;
// a key's keyup; a gamepad's stick back to the centre or the gamepad lost: hold/gamepad.js), the
// window losing focus, the tab hidden, the page hidden (pagehide), the RR session closing, and the
// panel itself (release(reason): stale state, a refused call, Halt, dispose).

import { holdButton } from "../robot/hold.js";

/**
 * @typedef {object} HoldMotion  how a panel moves its device while held
 * @property {(command: any) => void} start  begins (or replaces) the motion of `command`
 * @property {(reason: string) => void} stop  ends it; its own onStop then calls HoldToRun.stopped(reason)
 * @property {boolean} active  a motion is held
 */

export class HoldToRun {
  /**
   * @param {object} options
   * @param {HoldMotion} options.motion
   * @param {() => Promise<boolean>} [options.prepare]  before a hold starts (the robot's device lock); false: no hold
   * @param {() => void} [options.cancelled]  the control was let go while prepare() ran (undo it)
   * @param {(command: any, source: string) => void} [options.onStart]  a hold is about to start
   * @param {(error: unknown) => void} [options.onError]  makeCommand() threw: nothing was started
   * @param {(reason: string) => void} [options.onStop]  a hold ended (not for "replaced")
   * @param {object} [options.client]  the RR client of the device (its onClose ends the hold)
   * @param {EventTarget} [options.win]  window (a stand-in in tests)
   * @param {{visibilityState: string} & EventTarget} [options.doc]  document (a stand-in in tests)
   */
  constructor({ motion, prepare = null, cancelled = () => {}, onStart = () => {}, onError = () => {}, onStop = () => {},
    client = null, win = globalThis.window, doc = globalThis.document }) {
    if (!motion || typeof motion.start !== "function" || typeof motion.stop !== "function") throw new TypeError("HoldToRun needs a motion");
    Object.assign(this, { motion, prepare, cancelled, onStart, onError, onStop });
    this.pressId = 0;
    this.disposed = false;
    this.buttons = new Map();  // hold button -> removes its listeners
    this.followers = [];  // inputs told when a hold ended elsewhere (a gamepad must come back to the centre)
    this.source = null;   // what holds now: "pointer", "key", "gamepad"
    this.cleanups = [];
    const onBlur = () => this.release("blur");
    const onPageHide = () => this.release("pagehide");
    const onHidden = () => { if (doc.visibilityState === "hidden") this.release("hidden"); };
    win?.addEventListener("blur", onBlur);
    win?.addEventListener("pagehide", onPageHide);
    doc?.addEventListener("visibilitychange", onHidden);
    this.cleanups.push(() => {
      win?.removeEventListener("blur", onBlur);
      win?.removeEventListener("pagehide", onPageHide);
      doc?.removeEventListener("visibilitychange", onHidden);
    });
    const offClose = client?.onClose?.(() => this.release("session closed"));
    if (typeof offClose === "function") this.cleanups.push(offClose);
  }

  /** True while a motion is held. */
  get active() { return !!this.motion.active; }

  /**
   * Starts a hold of `makeCommand()` from input `source`. A command that cannot be made (makeCommand
   * throws) starts nothing and goes to onError. Resolves once started (or not).
   */
  async press(makeCommand, source = "pointer") {
    if (this.disposed) return false;
    const id = ++this.pressId;
    let command;
    try {
      command = makeCommand();
    } catch (e) {
      this.onError(e);
      return false;
    }
    if (this.prepare) {
      const ok = await this.prepare();
      if (!ok) return false;
      if (id !== this.pressId || this.disposed) { this.cancelled(); return false; }  // let go meanwhile
    }
    this.source = source;
    this.onStart(command, source);
    this.motion.start(command);
    return true;
  }

  /** Ends any hold (and a press still preparing); `reason` reaches onStop. */
  release(reason = "release") {
    this.pressId++;
    this.motion.stop(reason);
  }

  /** The motion's onStop: the hold has ended (clears the held buttons, re-arms the other inputs). */
  stopped(reason) {
    if (reason === "replaced") return;  // another control took over the hold
    const source = this.source;
    this.source = null;
    for (const b of this.buttons.keys()) b.classList.remove("held");
    for (const f of this.followers) f.holdEnded(reason, source);
    this.onStop(reason);
  }

  /** Makes `button` a hold control of makeCommand() (robot/hold.js holdButton); returns it. */
  button(button, makeCommand) {
    this.buttons.set(button, holdButton(button, () => this.press(makeCommand, "pointer"), (reason) => this.release(reason)));
    return button;
  }

  /** Forgets buttons that leave the page (the joints table rebuilt): their listeners go. */
  forgetButtons(list) {
    for (const b of list) { this.buttons.get(b)?.(); this.buttons.delete(b); }
  }

  /** An input told of every hold's end: `{ holdEnded(reason, source) }` (hold/gamepad.js). */
  follow(input) {
    this.followers.push(input);
    return () => { this.followers = this.followers.filter((f) => f !== input); };
  }

  dispose() {
    this.release("dispose");
    this.disposed = true;
    for (const c of this.cleanups) c();
    this.cleanups = [];
    this.forgetButtons([...this.buttons.keys()]);
  }
}
