// One picture fed with frames of a type whose renderer has a picture hook (std/registry.js: the
// standard Image or CompressedImage, or a page's own type; a camera stream, a captured frame, a
// property or function result): frames are decoded by that renderer, off the page's thread when it
// hands them to the image Worker (std/frame_decoder.js, the newest winning), and drawn at most once
// per animation frame. Beside the picture: its size and
// encoding (the depth range for depth images), the frame rate drawn, the frame's age from its own
// timestamp (image_info.data_header.ts, when its clock can be compared with the page's) and how many
// frames were dropped for newer ones. A bad frame (short data, unknown encoding, corrupt JPEG, step
// below a row, ...) leaves the last good picture in place and says what is wrong with it until a
// newer good frame comes.
//
// For tests and tools the figure carries data-received, data-drawn, data-errors, data-error-code,
// data-width, data-height, data-encoding, data-dropped and data-age-ms.

import { h } from "../dom.js";
import { FrameDecoder } from "../std/frame_decoder.js";
import { timeSeconds, comparableClock, durationText } from "../std/datetime.js";

const RATE_WINDOW_MS = 2000;

/** { seconds, comparable } of a frame's own timestamp, or null when it has none (or it is zero). */
export function frameTime(value, clockEnum) {
  try {
    const ts = value?.image_info?.data_header?.ts;
    const seconds = timeSeconds(ts);
    if (!seconds) return null;
    return { seconds, comparable: comparableClock(ts.clock_info?.clock_type, clockEnum) };
  } catch {
    return null;
  }
}

export class FrameView {
  /**
   * @param {HTMLElement} parent
   * @param {object} [opts]
   * @param {object} [opts.renderer]  the frames' renderer (its picture hooks draw them; push() may name another)
   * @param {object} [opts.context]  what the renderer's hooks get: { encodings, clockEnum, outline } of
   *   the device (views/context.js `text`)
   * @param {string} [opts.label]  the canvas's accessible name
   * @param {Function|null} [opts.Worker]  for FrameDecoder (null: decode on the page)
   */
  constructor(parent, opts = {}) {
    this.renderer = opts.renderer ?? null;
    this.context = opts.context ?? {};
    this.clockEnum = this.context.clockEnum;
    this.canvas = h("canvas", { class: "image frame-canvas", "aria-label": opts.label || "image", hidden: true });
    this.status = h("figcaption", { class: "frame-status" });
    this.errorEl = h("div", { class: "frame-error", role: "status", hidden: true });
    this.el = h("figure", { class: "frame-view" }, this.canvas, this.status, this.errorEl);
    parent.append(this.el);
    this.received = 0;
    this.drawn = 0;
    this.errors = 0;
    this.errorSeq = 0;
    this.shownSeq = 0;
    this.pending = null;
    this.frame = 0;
    this.drawTimes = [];
    this.last = null;  // what the drawn frame was
    this.decoder = new FrameDecoder({ onResult: (r, meta) => this.result(r, meta), Worker: opts.Worker });
    this.timer = setInterval(() => this.updateStatus(), 1000);
    this.updateStatus();
  }

  /** Shows `value`, drawn by `renderer` (default the view's); its data may be handed to the decoder. */
  push(value, renderer = this.renderer) {
    this.received++;
    this.el.dataset.received = String(this.received);
    const ts = frameTime(value, this.clockEnum);
    this.decoder.submit(value, { renderer, context: this.context }, { ts });
  }

  result(r, meta) {
    if (!r.ok) {
      this.errors++;
      this.errorSeq = Math.max(this.errorSeq, meta.seq);
      const what = r.error?.message || "the frame could not be drawn";
      this.errorEl.textContent = `frame ${meta.seq}: ${what}${this.drawn ? " (showing the last good frame)" : ""}`;
      this.errorEl.hidden = false;
      this.el.dataset.errors = String(this.errors);
      this.el.dataset.errorCode = r.error?.code || "error";
      this.el.classList.add("has-frame-error");
      return;
    }
    if (meta.seq < this.shownSeq) { r.bitmap?.close?.(); return; }
    this.shownSeq = meta.seq;
    this.pending?.result.bitmap?.close?.();
    this.pending = { result: r, meta };
    if (meta.seq > this.errorSeq) {
      this.errorEl.hidden = true;
      this.errorEl.textContent = "";
      delete this.el.dataset.errorCode;
      this.el.classList.remove("has-frame-error");
    }
    if (!this.frame) this.frame = requestAnimationFrame(() => this.draw());
  }

  draw() {
    this.frame = 0;
    const p = this.pending;
    this.pending = null;
    if (!p) return;
    const { result: r, meta } = p;
    const bitmap = r.bitmap;
    try {
      if (this.canvas.width !== bitmap.width) this.canvas.width = bitmap.width;
      if (this.canvas.height !== bitmap.height) this.canvas.height = bitmap.height;
      const g = this.canvas.getContext("2d");
      g.clearRect(0, 0, bitmap.width, bitmap.height);
      g.drawImage(bitmap, 0, 0);
    } catch (e) {
      this.result({ ok: false, error: { code: "draw_failed", message: `not drawn: ${e?.message || e}` } }, meta);
      return;
    } finally {
      bitmap.close?.();
    }
    this.canvas.hidden = false;
    this.drawn++;
    const now = performance.now();
    this.drawTimes.push(now);
    while (this.drawTimes.length && this.drawTimes[0] < now - RATE_WINDOW_MS) this.drawTimes.shift();
    this.last = {
      width: r.width, height: r.height, what: r.encoding || r.format?.name || "", range: r.range ?? null,
      note: r.note || "", ts: meta.ts,
    };
    const d = this.el.dataset;
    d.drawn = String(this.drawn);
    d.width = String(r.width);
    d.height = String(r.height);
    d.encoding = this.last.what;
    this.canvas.dataset.frames = String(this.drawn);
    this.updateStatus();
  }

  /** Frames drawn per second over the last two seconds: 0 when none, null when one (no rate yet). */
  rate() {
    const now = performance.now();
    const recent = this.drawTimes.filter((t) => t >= now - RATE_WINDOW_MS);
    if (recent.length < 2) return recent.length ? null : 0;
    return (recent.length - 1) * 1000 / Math.max(1, now - recent[0]);
  }

  updateStatus() {
    const parts = [];
    const l = this.last;
    if (!l) {
      parts.push(this.received ? "no frame drawn yet" : "no frame yet");
    } else {
      parts.push(`${l.width}×${l.height} ${l.what}`.trim());
      if (l.range) parts.push(`depth ${fmt(l.range.min)}–${fmt(l.range.max)}`);
      const rate = this.rate();
      if (rate !== null) parts.push(`${rate.toFixed(1)} fps`);
      if (l.ts) {
        const age = Date.now() / 1000 - l.ts.seconds;
        parts.push(l.ts.comparable ? ageWords(age) : "age unknown (device clock)");
        if (l.ts.comparable) this.el.dataset.ageMs = String(Math.round(age * 1000));
      }
      if (l.note) parts.push(l.note);
    }
    const dropped = this.decoder.stats.dropped;
    if (dropped) parts.push(`${dropped} dropped for newer`);
    this.el.dataset.dropped = String(dropped);
    this.status.textContent = parts.join(" · ");
  }

  dispose() {
    clearInterval(this.timer);
    if (this.frame) cancelAnimationFrame(this.frame);
    this.pending?.result.bitmap?.close?.();
    this.pending = null;
    this.decoder.dispose();
    this.el.remove();
  }
}

/** "80 ms old", or "1.2 s ahead of this page's clock" for a frame stamped in the page's future. */
export function ageWords(ageSeconds) {
  return ageSeconds > -0.0005 ? `${durationText(Math.max(0, ageSeconds))} old` : `${durationText(-ageSeconds)} ahead of this page's clock`;
}

function fmt(x) {
  return Number.isInteger(x) ? String(x) : String(Number(Number(x).toPrecision(4)));
}
