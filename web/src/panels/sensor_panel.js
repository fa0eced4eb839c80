// The sensor panel, for the standard sensors (com.robotraconteur.sensor Sensor, FreeformSensor,
// Vector2/3/6Sensor, WrenchSensor): what the sensor is (sensor_info: type, rate, resolution, units),
// its newest value as named axes with units (force and torque for a wrench), the rate the page
// receives it at, a live plot per axis, and the parameter control for users allowed to call
// getf_param / setf_param. The value wire is chosen by sensor/sensor_source.js; a device whose
// definitions give none of them the standard type gets a one-line note and the generic view below.

import { h, errorText } from "../dom.js";
import { describeMember } from "../views/context.js";
import { errorLine, whenAccess } from "./panel_parts.js";
import { objectTypes } from "./registry.js";
import { SENSOR_TYPES, sensorSource, sensorAxes, infoUnits, axisText, sensorTitle } from "../sensor/sensor_source.js";
import { buildParamControl, parameterNames } from "./param_control.js";
import { typedText } from "../std/typed_text.js";

/** Samples per second over the last `windowMs` of arrival times. */
export class RateMeter {
  constructor(windowMs = 2000) { this.windowMs = windowMs; this.times = []; }
  tick(now = performance.now()) {
    this.times.push(now);
    while (this.times.length && this.times[0] < now - this.windowMs) this.times.shift();
  }
  rate(now = performance.now()) {
    const recent = this.times.filter((t) => t >= now - this.windowMs);
    return recent.length < 2 ? 0 : ((recent.length - 1) * 1000) / (recent[recent.length - 1] - recent[0] || 1);
  }
}

export function createSensorPanel(parent, ctx) {
  const { obj, view } = ctx;
  const members = obj.$members || [];
  const find = (name, kind) => members.find((m) => m.name === name && m.kind === kind) || null;
  const describe = (m) => describeMember(view, obj, m);
  let disposed = false;
  const cleanups = [];

  const errors = errorLine("sensor-error", () => !disposed);
  const error = errors.el, showError = errors.show;
  const info = h("dl", { class: "camera-info-rows sensor-info" });
  const rate = h("output", { class: "sensor-rate" });
  const table = h("table", { class: "sensor-values" });
  const plotBox = h("div", { class: "sensor-plot" });
  const params = h("div", { class: "sensor-params" });
  const source = sensorSource(members.filter((m) => m.kind === "wire" && !m.writeonly), describe);
  const title = h("h3", { text: sensorTitle(source, objectTypes(obj)) });
  const el = h("section", { class: "panel sensor-panel", dataset: { panel: "sensor", source: source?.member ?? "" } },
    title, info, error, rate, table, plotBox, params);
  parent.append(el);

  const addRow = (label, text) => info.append(h("dt", { text: label }), h("dd", { text, dataset: { row: label } }));
  let units = [];
  let paramNames = [];

  // sensor_info: read once, for the units of the values and the parameter names
  const infoMember = find("sensor_info", "property");
  const infoType = infoMember ? describe(infoMember)?.type : null;
  const fieldOf = (name) => infoType?.fields?.find((f) => f.name === name);
  const infoRead = infoMember && infoType?.fields && !infoMember.writeonly
    ? obj.sensor_info.get().then((v) => {
      if (disposed || !v) return;
      units = infoUnits(v);
      paramNames = parameterNames(v.parameter_info);
      const t = fieldOf("sensor_type");
      if (t && v.sensor_type !== undefined) addRow("type", typedText(v.sensor_type, t.type, view?.text));
      if (typeof v.update_frequency === "number" && v.update_frequency > 0) addRow("update rate", `${axisText(v.update_frequency)} Hz`);
      if (units.length) addRow("units", units.join(", "));
      if (v.sensor_resolution?.length) addRow("resolution", Array.from(v.sensor_resolution, axisText).join(", "));
      if (typeof v.analog_sensor === "boolean") addRow("analog", v.analog_sensor ? "yes" : "no");
      el.dataset.info = "read";
    }, (e) => showError(`sensor_info: ${errorText(e)}`))
    : Promise.resolve();

  if (!source) {
    el.dataset.fallback = "true";
    el.append(h("div", { class: "hint sensor-fallback", text: "no sensor value wire of a standard type on this device: its members are shown below" }));
  } else {
    const meter = new RateMeter();
    // the plot's module (uPlot) loads with the first panel that needs it, not with the registry
    let plot = null, samples = 0;
    import("../live_plot.js").then(({ LivePlot }) => {
      if (!disposed) plot = new LivePlot(plotBox, { windowSeconds: 20 });
    }, (e) => showError(`plot: ${errorText(e)}`));
    cleanups.push(() => plot?.dispose());
    let newest = null, frame = 0, rows = new Map();
    const draw = () => {
      frame = 0;
      if (disposed || !newest) return;
      const axes = sensorAxes(source, newest, units);
      for (const a of axes) {
        let row = rows.get(a.name);
        if (!row) {
          row = { value: h("td", { class: "sensor-value" }), unit: h("td", { class: "sensor-unit" }) };
          rows.set(a.name, row);
          table.append(h("tr", { dataset: { axis: a.name } }, h("th", { text: a.name }), row.value, row.unit));
        }
        row.value.textContent = a.text ?? axisText(a.value);
        row.unit.textContent = a.unit ?? "";
      }
      rate.textContent = `${axisText(Math.round(meter.rate() * 10) / 10)} samples/s`;
    };
    const follow = ctx.live.followWire(source.member, {
      onValue: (v) => {
        newest = v;
        meter.tick();
        const axes = sensorAxes(source, v, units).filter((a) => typeof a.value === "number" && Number.isFinite(a.value));
        if (axes.length) plot?.push(axes.map((a) => [a.unit ? `${a.name} (${a.unit})` : a.name, a.value]));
        el.dataset.samples = String(++samples);
        if (!frame) frame = requestAnimationFrame(draw);
      },
      onError: errors.onMemberError(source.member),
    });
    cleanups.push(() => { follow.dispose(); if (frame) cancelAnimationFrame(frame); });
  }

  // the parameter control, for users allowed to call getf_param / setf_param
  whenAccess(ctx, el, infoRead, () => !disposed,
    (access) => buildParamControl(params, { obj, view, access, names: paramNames, onError: showError }), showError);

  return {
    el,
    dispose() {
      disposed = true;
      for (const c of cleanups) c();
      el.remove();
    },
  };
}

export const sensorPanel = { name: "sensor", order: 20, types: SENSOR_TYPES, create: createSensorPanel };
