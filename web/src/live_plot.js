// A rolling time plot (uPlot) of named numeric series, with a readout of the newest values that
// tests and people can read. Series are added as names first appear; the chart is rebuilt then.

import uPlot from "../vendor/uplot/uPlot.esm.js";
import { h } from "./dom.js";

const COLORS = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf", "#7f7f7f", "#bcbd22"];
const HIDDEN = /(^|[.\]])(time|timestamp|ts|seq|seqno|sequence|seqnum)$/i;

/** Axis label of a time in seconds since the epoch: local clock time, whole seconds. */
function clockLabel(t) {
  return new Date(t * 1000).toLocaleTimeString([], { hour12: false });
}

export class LivePlot {
  /**
   * @param {HTMLElement} parent  where the plot goes
   * @param {object} opts  { windowSeconds = 30, maxPoints = 1200, height = 140, hidden: RegExp (series off
   *   at first; clock-like names by default) }
   */
  constructor(parent, opts = {}) {
    this.windowSeconds = opts.windowSeconds ?? 30;
    this.maxPoints = opts.maxPoints ?? 1200;
    this.height = opts.height ?? 140;
    this.hidden = opts.hidden ?? HIDDEN;
    this.names = [];
    this.hiddenNames = new Set();
    this.data = [[]];
    this.count = 0;
    this.el = h("div", { class: "plot" });
    this.chartEl = h("div", { class: "plot-chart" });
    this.readout = h("div", { class: "plot-readout" });
    this.el.append(this.chartEl, this.readout);
    parent.append(this.el);
    this.chart = null;
    this.frame = 0;
    this.resizeObserver = new ResizeObserver(() => this.chart?.setSize(this.size()));
    this.resizeObserver.observe(this.chartEl);
  }

  size() { return { width: Math.max(200, this.chartEl.clientWidth || 360), height: this.height }; }

  /**
   * Adds a sample: `pairs` = [[seriesName, number, hiddenAtFirst?, label?], ...] at `t` (seconds since
   * the epoch, default now); the readout shows `label` (an enum's name) instead of the number when given.
   */
  push(pairs, t = performance.timeOrigin / 1000 + performance.now() / 1000) {
    if (!pairs.length) return;
    let rebuilt = false;
    for (const [name, , hide] of pairs) {
      if (!this.names.includes(name)) {
        this.names.push(name);
        if (hide || this.hidden.test(name)) this.hiddenNames.add(name);
        this.data.push(new Array(this.data[0].length).fill(null));
        rebuilt = true;
      }
    }
    this.data[0].push(t);
    const row = new Map(pairs);
    this.names.forEach((name, i) => this.data[i + 1].push(row.has(name) ? row.get(name) : null));
    const cutoff = t - this.windowSeconds;
    let drop = 0;
    while (drop < this.data[0].length - 1 && (this.data[0][drop] < cutoff || this.data[0].length - drop > this.maxPoints)) drop++;
    if (drop) this.data = this.data.map((s) => s.slice(drop));
    this.count++;
    this.el.dataset.samples = String(this.count);
    this.updateReadout(pairs);
    if (rebuilt) this.rebuild();
    else this.schedule();
  }

  updateReadout(pairs) {
    for (const [name, value, , label] of pairs) {
      let item = this.readout.querySelector(`[data-series="${CSS.escape(name)}"]`);
      if (!item) {
        const i = this.names.indexOf(name);
        item = h("button", {
          type: "button", class: "readout-item", dataset: { series: name }, title: "show or hide",
          onclick: () => this.toggle(name),
        },
          h("i", { class: "swatch", style: `background:${COLORS[i % COLORS.length]}` }),
          h("span", { class: "readout-name", text: name }), h("output", { class: "readout-value" }));
        this.readout.append(item);
      }
      item.querySelector("output").value = label ?? (Number.isInteger(value) ? String(value) : String(Number(value.toPrecision(5))));
      item.dataset.value = String(value);
      item.classList.toggle("off", this.hiddenNames.has(name));
    }
  }

  /** Shows or hides one series (kept across rebuilds). */
  toggle(name) {
    if (this.hiddenNames.has(name)) this.hiddenNames.delete(name); else this.hiddenNames.add(name);
    const i = this.names.indexOf(name);
    this.chart?.setSeries(i + 1, { show: !this.hiddenNames.has(name) });
    this.readout.querySelector(`[data-series="${CSS.escape(name)}"]`)?.classList.toggle("off", this.hiddenNames.has(name));
  }

  rebuild() {
    this.chart?.destroy();
    const series = [{}].concat(this.names.map((name, i) => ({
      label: name, stroke: COLORS[i % COLORS.length], width: 1.5, show: !this.hiddenNames.has(name), spanGaps: true,
      points: { show: false },
    })));
    this.chart = new uPlot({
      ...this.size(), series, legend: { show: false },
      cursor: { drag: { x: false, y: false } },
      scales: { x: { time: true } },
      axes: [
        { stroke: "#555", grid: { stroke: "#eee" }, incrs: [1, 2, 5, 10, 15, 30, 60, 120, 300], values: (u, splits) => splits.map(clockLabel) },
        { stroke: "#555", grid: { stroke: "#eee" }, size: 60 },
      ],
    }, this.data, this.chartEl);
  }

  schedule() {
    if (this.frame) return;
    this.frame = requestAnimationFrame(() => {
      this.frame = 0;
      this.chart?.setData(this.data);
    });
  }

  dispose() {
    if (this.frame) cancelAnimationFrame(this.frame);
    this.resizeObserver.disconnect();
    this.chart?.destroy();
    this.el.remove();
  }
}
