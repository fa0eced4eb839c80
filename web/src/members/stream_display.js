// What wires and pipes show for each value: pictures (values whose renderer draws them: the standard
// Image, CompressedImage, a page's own picture types, or arrays and maps of them) in FrameViews, other image-like values (a struct with width, height, data, as the
// demo webcam's WebcamImage) on a canvas, and otherwise the value's readable text (std/typed_text.js)
// and a live plot of its numbers (std/plot_fields.js: no UUID bytes, identifiers or clock fields; the
// value's own timestamp on the time axis when it carries one). Text and the plain canvas are drawn at
// most once per animation frame; the newest value wins.

import { h } from "../dom.js";
import { formatValue } from "../std/value_text.js";
import { asImage, drawImage } from "../image_view.js";
import { LivePlot } from "../live_plot.js";
import { typedText } from "../std/typed_text.js";
import { plotSample } from "../views/plot_sample.js";
import { hasImages, picturesOf, ImageSet } from "../views/image_set.js";

export class StreamDisplay {
  /**
   * @param {HTMLElement} parent
   * @param {object} [opts]
   * @param {object|null} [opts.type]  the value's type descriptor (std/describe.js); its named type picks
   *   a known byte layout (packet_layouts.js)
   * @param {object} [opts.view]  the device's view context (views/context.js)
   * @param {string} [opts.label]  what the pictures are called
   */
  constructor(parent, opts = {}) {
    this.type = opts.type ?? null;
    this.qualifiedType = this.type?.qualified ?? null;
    this.view = opts.view ?? null;
    this.label = opts.label || "stream";
    this.pictures = hasImages(this.type);
    this.text = h("output", { class: "value" });
    this.canvas = h("canvas", { class: "image", hidden: true });
    this.stats = h("span", { class: "stream-stats" });
    this.el = h("div", { class: "stream" }, this.stats, this.text, this.canvas);
    parent.append(this.el);
    this.images = null;
    this.plot = null;
    this.latest = undefined;
    this.latestText = null;
    this.count = 0;
    this.frame = 0;
    this.rateStart = performance.now();
    this.rateCount = 0;
    this.lastT = -Infinity;
  }

  /** Shows `value` (pictures go to their decoder now; numbers to the plot now, so no sample is lost). */
  push(value) {
    this.latest = value;
    this.count++;
    this.rateCount++;
    try {
      if (this.pictures) {
        // text first: the pictures' bytes may be handed to the decoder's Worker
        this.latestText = this.describe(value);
        this.images ??= new ImageSet(this.el, { context: this.view?.text, label: this.label });
        this.images.push(picturesOf(value, this.type));
      } else if (!asImage(value)) {
        const { pairs, t } = plotSample(value, this.type, this.qualifiedType);
        if (pairs.length) {
          this.plot ??= new LivePlot(this.el);
          // the value's own clock when it has one (never going back: the plot's times must rise)
          const time = t !== null && t >= this.lastT ? t : undefined;
          if (time !== undefined) this.lastT = time;
          this.plot.push(pairs, time);
        }
      }
    } catch (e) {
      this.latestText = `(not shown: ${e?.message || e})`;
    }
    if (!this.frame) this.frame = requestAnimationFrame(() => this.draw());
  }

  describe(v) {
    if (!this.type) return formatValue(v, 16);
    return typedText(v, this.type, this.view?.text, 16);
  }

  draw() {
    this.frame = 0;
    const v = this.latest;
    if (this.pictures) {
      this.text.textContent = this.latestText ?? "";
    } else {
      const image = asImage(v);
      this.canvas.hidden = !image;
      if (image) {
        drawImage(this.canvas, image);
        this.canvas.dataset.frames = String(this.count);
        this.text.textContent = `${image.width}×${image.height}, ${image.channels} channel(s)`;
      } else {
        try { this.text.textContent = this.describe(v); } catch (e) { this.text.textContent = formatValue(v, 16); }
      }
    }
    const now = performance.now();
    if (now - this.rateStart >= 1000) {
      this.rate = (this.rateCount * 1000) / (now - this.rateStart);
      this.rateStart = now;
      this.rateCount = 0;
    }
    this.stats.textContent = `${this.count} received${this.rate !== undefined ? `, ${this.rate.toFixed(1)}/s` : ""}`;
    this.el.dataset.count = String(this.count);
  }

  dispose() {
    if (this.frame) cancelAnimationFrame(this.frame);
    this.images?.dispose();
    this.plot?.dispose();
    this.el.remove();
  }
}
