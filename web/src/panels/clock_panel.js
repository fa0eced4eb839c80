// The clock panel, for com.robotraconteur.datetime.clock.Clock: the device's time (time_utc) and local
// time (time_local) live, how far the device's clock is ahead of or behind this browser's (the newest
// value against the browser's clock when it arrived: the transport's delay counts against the device),
// and clock_info (clock type, time zone). A clock without a time_utc wire of the standard type gets one
// line saying so and the generic member view below.

import { h, errorText } from "../dom.js";
import { describeMember } from "../views/context.js";
import { enumName } from "../std/enums.js";
import { errorLine } from "./panel_parts.js";
import { clockOffset, offsetText, clockText, zoneText, onePod } from "../clock/clock.js";

export const CLOCK = "com.robotraconteur.datetime.clock.Clock";

export function createClockPanel(parent, ctx) {
  const { obj, view } = ctx;
  const wireOf = (name, type) => {
    const m = (obj.$members || []).find((x) => x.name === name && x.kind === "wire" && !x.writeonly);
    return m && describeMember(view, obj, m)?.type?.qualified === type ? m : null;
  };
  const clockEnum = view?.outline?.types?.get("com.robotraconteur.datetime.ClockTypeCode")?.values ?? [];
  let disposed = false, frame = 0, utc = null, utcAt = 0, local = null, info = null, count = 0;
  const errors = errorLine("clock-error", () => !disposed);
  const rows = h("dl", { class: "camera-info-rows clock-rows" });
  const el = h("section", { class: "panel clock-panel", dataset: { panel: "clock", samples: "0" } }, h("h3", { text: "Clock" }), errors.el, rows);
  parent.append(el);
  const utcWire = wireOf("time_utc", "com.robotraconteur.datetime.DateTimeUTC");
  if (!utcWire) {
    el.dataset.fallback = "true";
    rows.replaceChildren(h("span", { class: "hint", text: "this clock has no time_utc wire of the standard DateTimeUTC type: its members are shown below" }));
    return { el, dispose() { el.remove(); } };
  }
  const localWire = wireOf("time_local", "com.robotraconteur.datetime.DateTimeLocal");
  function draw() {
    frame = 0;
    if (disposed) return;
    const list = [];
    if (utc) {
      const offset = clockOffset(utc, utcAt);
      list.push(["time_utc", "time (UTC)", clockText(utc)], ["offset", "ahead of this browser", offsetText(offset)]);
      el.dataset.offsetMs = offset === null ? "" : String(Math.round(offset * 1000));
      const type = onePod(utc)?.clock_info?.clock_type;
      if (type !== undefined) list.push(["clock_type", "clock", enumName(clockEnum, type) ?? String(type)]);
    }
    if (local) list.push(["time_local", "local time", clockText(local)]);
    if (info) list.push(["timezone", "time zone", zoneText(info)]);
    rows.replaceChildren(...list.flatMap(([k, l, t]) => [h("dt", { text: l }), h("dd", { dataset: { row: k }, text: t })]));
    el.dataset.samples = String(count);
  }
  const schedule = () => { if (!frame) frame = requestAnimationFrame(draw); };
  const follows = [ctx.live.followWire(utcWire.name, { onValue: (v) => { utc = v; utcAt = Date.now(); count++; schedule(); }, onError: errors.onMemberError(utcWire.name) })];
  if (localWire) follows.push(ctx.live.followWire(localWire.name, { onValue: (v) => { local = v; schedule(); }, onError: errors.onMemberError(localWire.name) }));
  if ((obj.$members || []).some((m) => m.name === "clock_info" && m.kind === "property")) {
    obj.clock_info.get().then((i) => { info = i; schedule(); }, (e) => errors.show(`clock_info: ${errorText(e)}`));
  }
  return { el, dispose() { disposed = true; for (const f of follows) f.dispose(); if (frame) cancelAnimationFrame(frame); el.remove(); } };
}

export const clockPanel = { name: "clock", order: 20, types: [CLOCK], create: createClockPanel };
