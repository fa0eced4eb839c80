// The timeline under a replayed device (issue 44, docs/recording.md "Replay"): play/pause, a seek
// slider with the position and the file's time span, the speed and loop, and the replay's state and
// error, from GET api/replays/<name> every half second; changes go to POST api/replays/<name>.
// The gateway lets only users with `write` on the device control it: without it the controls are
// disabled (the status is still shown).

import { h, errorText } from "../dom.js";
import { formatSeconds, timeSpan, replayStatus, controlReplay } from "./recording_api.js";
import { StatusOrder } from "../status_order.js";

const POLL_MS = 500;
/** Speed factors offered (any positive factor is accepted by the gateway). */
export const SPEEDS = Object.freeze([0.25, 0.5, 1, 2, 4, 10]);

export class ReplayTimeline {
  /**
   * @param {HTMLElement} parent
   * @param {{name: string, status: object, mayControl?: boolean, fetchImpl?: Function}} opts
   *   status: the replay's first status (GET api/replays); mayControl false: controls disabled
   */
  constructor(parent, { name, status, mayControl = true, fetchImpl = globalThis.fetch }) {
    this.name = name;
    this.fetchImpl = fetchImpl;
    this.mayControl = mayControl;
    this.order = new StatusOrder();
    this.playButton = h("button", { type: "button", class: "replay-play", text: "Play", onclick: () => this.send({ state: this.status?.state === "playing" ? "paused" : "playing" }) });
    // the slider works in milliseconds; while it is dragged the polled position does not move it
    this.slider = h("input", { type: "range", class: "replay-seek", min: 0, max: 0, step: 1, value: 0, "aria-label": "replay position" });
    this.slider.addEventListener("input", () => { this.dragging = true; this.position.textContent = formatSeconds(this.slider.value / 1000); });
    this.slider.addEventListener("change", () => { this.dragging = false; this.send({ position_s: Number(this.slider.value) / 1000 }); });
    this.position = h("span", { class: "replay-position" });
    this.duration = h("span", { class: "replay-duration" });
    this.speed = h("select", { class: "replay-speed", "aria-label": "speed", onchange: () => this.send({ speed: Number(this.speed.value) }) },
      ...SPEEDS.map((s) => h("option", { value: String(s), text: `${s}×` })));
    this.loop = h("input", { type: "checkbox", class: "replay-loop", onchange: () => this.send({ loop: this.loop.checked }) });
    this.state = h("span", { class: "badge replay-state" });
    this.span = h("span", { class: "replay-span" });
    this.file = h("code", { class: "replay-file" });
    this.error = h("p", { class: "replay-error", role: "alert", hidden: true });
    this.el = h("section", { class: "replay-timeline", dataset: { device: name } },
      h("h3", { text: "Replay" }),
      h("div", { class: "replay-row" }, h("span", { class: "state-label", text: "file" }), this.file, this.span),
      h("div", { class: "replay-row" }, this.playButton, this.position, this.slider, this.duration, this.state),
      h("div", { class: "replay-row" },
        h("label", {}, h("span", { text: "Speed" }), this.speed),
        h("label", {}, this.loop, h("span", { text: "Loop" }))),
      mayControl ? null : h("p", { class: "hint", text: "Your login may not control this replay (it needs write on the device)." }),
      this.error);
    for (const c of [this.playButton, this.slider, this.speed, this.loop]) c.disabled = !mayControl;
    parent.append(this.el);
    this.show(status);
    this.timer = setInterval(() => this.poll(), POLL_MS);
  }

  showError(text) {
    this.error.textContent = text || "";
    this.error.hidden = !text;
  }

  async poll() {
    const ticket = this.order.beginPoll();
    if (!ticket) return;
    try {
      const s = await replayStatus(this.name, this.fetchImpl);
      if (this.order.accept(ticket)) this.show(s);
    } catch (e) {
      if (e.status && this.order.accept(ticket)) this.showError(errorText(e));
    }
  }

  // The controls keep the user's change on screen until the gateway's reply to it (StatusOrder).
  async send(change) {
    this.showError("");
    const ticket = this.order.beginChange();
    let failed = null;
    try {
      const s = await controlReplay(this.name, change, this.fetchImpl);
      if (this.order.accept(ticket)) this.show(s);
    } catch (e) {
      failed = e;
    } finally {
      this.order.endChange();
    }
    if (failed) {
      this.showError(errorText(failed));
      this.poll();
    }
  }

  /** Shows a status: {state, position_s, duration_s, start_ns, speed, loop, file, error?}. */
  show(s) {
    if (this.disposed || !s) return;
    this.status = s;
    this.el.dataset.state = s.state;
    this.state.textContent = s.state;
    this.state.dataset.state = s.state === "playing" ? "connected" : s.state === "failed" ? "failed" : "idle";
    this.playButton.textContent = s.state === "playing" ? "Pause" : "Play";
    this.file.textContent = s.file;
    const durMs = Math.round((s.duration_s || 0) * 1000);
    this.slider.max = String(durMs);
    if (!this.dragging) {
      this.slider.value = String(Math.round((s.position_s || 0) * 1000));
      this.position.textContent = formatSeconds(s.position_s);
    }
    this.el.dataset.position = String(s.position_s);
    this.duration.textContent = formatSeconds(s.duration_s);
    if (document.activeElement !== this.speed) {
      if (![...this.speed.options].some((o) => Number(o.value) === s.speed)) this.speed.append(h("option", { value: String(s.speed), text: `${s.speed}×` }));
      this.speed.value = String(s.speed);
    }
    this.loop.checked = !!s.loop;
    const span = timeSpan(s.start_ns, s.duration_s);
    this.span.textContent = span ? `recorded ${span.start} – ${span.end}` : "";
    if (s.state === "failed") this.showError(s.error || "replay failed");
  }

  dispose() {
    this.disposed = true;
    clearInterval(this.timer);
    this.el.remove();
  }
}
