// What wires and pipes show for each value: an image on a canvas when the value is one, else the
// value's text and a live plot of its numbers. Drawing waits for the next animation frame, so a fast
// stream costs one draw per frame.

import { h } from "../dom.js";
import { formatValue } from "../value_codec.js";
import { asImage, drawImage } from "../image_view.js";
import { numericFields } from "../numeric_fields.js";
import { LivePlot } from "../live_plot.js";

export class StreamDisplay {
  /** @param {HTMLElement} parent @param {string|null} qualifiedType  the value's struct type, for known layouts */
  constructor(parent, qualifiedType) {
    this.qualifiedType = qualifiedType;
    this.text = h("output", { class: "value" });
    this.canvas = h("canvas", { class: "image", hidden: true });
    this.stats = h("span", { class: "stream-stats" });
    this.el = h("div", { class: "stream" }, this.stats, this.text, this.canvas);
    parent.append(this.el);
    this.plot = null;
    this.latest = undefined;
    this.count = 0;
    this.frame = 0;
    this.rateStart = performance.now();
    this.rateCount = 0;
  }

  /** Shows `value` (and adds its numbers to the plot now, so no sample is lost). */
  push(value) {
    this.latest = value;
    this.count++;
    this.rateCount++;
    const image = asImage(value);
    if (!image) {
      const pairs = numericFields(value, this.qualifiedType);
      if (pairs.length) {
        this.plot ??= new LivePlot(this.el);
        this.plot.push(pairs);
      }
    }
    if (!this.frame) this.frame = requestAnimationFrame(() => this.draw());
  }

  draw() {
    this.frame = 0;
    const v = this.latest;
    const image = asImage(v);
    this.canvas.hidden = !image;
    if (image) {
      drawImage(this.canvas, image);
      this.canvas.dataset.frames = String(this.count);
      this.text.textContent = `${image.width}×${image.height}, ${image.channels} channel(s)`;
    } else {
      this.text.textContent = formatValue(v, 16);
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
    this.plot?.dispose();
    this.el.remove();
  }
}
