// Hold-to-jog: while a jog control is held, the same jog call is sent at once and then every 50 ms,
// each with a short timeout (0.15 s) after which the robot stops by itself. Stopping is simply not
// sending: whatever ends the hold (release, a lost page, network or gateway), the robot stops within
// the timeout. Calls never pile up: at most JOG_MAX_IN_FLIGHT are outstanding, beyond that a tick is
// skipped. Two rather than one keep the robot moving while a round trip is longer than the timeout (a
// busy machine), and bound what can still arrive after the hold ends to two calls. A refused or failed
// call ends the hold and is reported. No DOM here, so the timing is tested with fake timers.

/** Seconds the robot keeps jogging after the last call (the robdef's `timeout` argument). */
export const JOG_TIMEOUT_S = 0.15;
/** Milliseconds between two jog calls while a control is held. */
export const JOG_PERIOD_MS = 50;
/** Jog calls outstanding at most (of this hold and earlier ones together). */
export const JOG_MAX_IN_FLIGHT = 2;

export class JogRepeater {
  /**
   * @param {object} options
   * @param {(command: any) => Promise<unknown>} options.send  makes one jog call (e.g. jog_joint(v, 0.15, false))
   * @param {(error: unknown, command: any) => void} [options.onError]  a call failed: the hold has ended
   * @param {(reason: string) => void} [options.onStop]  the hold ended ("release", "error", "blur", ...)
   * @param {number} [options.periodMs]  JOG_PERIOD_MS unless a test says otherwise
   * @param {{setInterval: Function, clearInterval: Function}} [options.timers]  globalThis unless a test says otherwise
   */
  constructor({ send, onError = () => {}, onStop = () => {}, periodMs = JOG_PERIOD_MS, timers = globalThis }) {
    if (typeof send !== "function") throw new TypeError("JogRepeater needs send(command)");
    this.send = send;
    this.onError = onError;
    this.onStop = onStop;
    this.periodMs = periodMs;
    this.timers = timers;
    this.command = null;
    this.timer = null;
    this.hold = 0;          // id of the current hold; a late answer of an earlier hold is ignored
    this.inFlight = 0;  // calls outstanding (of this or earlier holds)
    this.sent = 0;
    this.skipped = 0;
  }

  /** True while a control is held (calls are being sent). */
  get active() { return this.timer !== null; }

  /** Starts holding `command` (ends a hold of another command first): one call now, then one per period. */
  start(command) {
    if (this.active) this.stop("replaced");
    this.command = command;
    const hold = ++this.hold;
    this.timer = this.timers.setInterval(() => this.tick(hold), this.periodMs);
    this.tick(hold);
  }

  tick(hold) {
    if (hold !== this.hold || !this.active) return;
    if (this.inFlight >= JOG_MAX_IN_FLIGHT) { this.skipped++; return; }
    this.inFlight++;
    this.sent++;
    const command = this.command;
    let call;
    try {
      call = Promise.resolve(this.send(command));
    } catch (e) {
      call = Promise.reject(e);
    }
    call.then(() => { this.inFlight--; }, (e) => {
      this.inFlight--;
      if (hold !== this.hold || !this.active) return;  // the hold ended meanwhile: nothing to stop
      this.stop("error");
      this.onError(e, command);
    });
  }

  /** Ends the hold (no further calls); `reason` is passed to onStop. Does nothing when not holding. */
  stop(reason = "release") {
    if (!this.active) return;
    this.timers.clearInterval(this.timer);
    this.timer = null;
    this.hold++;
    this.command = null;
    this.onStop(reason);
  }
}
