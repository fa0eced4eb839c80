// The event log panel, for com.robotraconteur.eventlog EventLog and EventLogDevice: the newest messages
// (up to 200 read with getf_eventlog_messages from eventlog_info's message numbers) and every message
// the eventlog_message_stream pipe brings while the page is open, newest first (1,000 kept), as a table
// of number, time, level, source, title and message, filtered by words typed and a lowest level. A log
// without eventlog_info and getf_eventlog_messages gets one line saying so and the generic view below.

import { h, errorText } from "../dom.js";
import { errorLine } from "./panel_parts.js";
import { messageRow, passes, mergeRows, newestWindow } from "../eventlog/event_log.js";

const E = "com.robotraconteur.eventlog";
export const EVENT_LOG_TYPES = [`${E}.EventLog`, `${E}.EventLogDevice`];

export function createEventLogPanel(parent, ctx) {
  const { obj, view } = ctx;
  const has = (name, kind) => (obj.$members || []).some((m) => m.name === name && m.kind === kind);
  const levels = view?.outline?.types?.get(`${E}.EventLogLevel`)?.values ?? [];
  let disposed = false, rows = [], frame = 0, pipe = null;
  const errors = errorLine("eventlog-error", () => !disposed);
  const filter = h("input", { type: "search", name: "eventlog-filter", placeholder: "filter: words in level, source, title or message", "aria-label": "filter", size: "40" });
  const minLevel = h("select", { name: "eventlog-level", "aria-label": "lowest level" }, h("option", { value: "0", text: "all levels" }),
    ...levels.filter((l) => l.value > 0).map((l) => h("option", { value: String(l.value), text: `${l.name} and above` })));
  const count = h("span", { class: "hint eventlog-count" });
  const tbody = h("tbody");
  const table = h("table", { class: "robot-joints eventlog-table" },
    h("thead", {}, h("tr", {}, ...["#", "time", "level", "source", "title", "message"].map((t) => h("th", { text: t })))), tbody);
  const el = h("section", { class: "panel eventlog-panel", dataset: { panel: "eventlog", messages: "0" } },
    h("h3", { text: "Event log" }), errors.el, h("div", { class: "camera-controls" }, filter, minLevel, count), table);
  parent.append(el);
  if (!has("eventlog_info", "property") || !has("getf_eventlog_messages", "function")) {
    el.dataset.fallback = "true";
    table.hidden = true;
    el.append(h("div", { class: "hint", text: "this log has no eventlog_info and getf_eventlog_messages of the standard: its members are shown below" }));
    return { el, dispose() { el.remove(); } };
  }
  function draw() {
    frame = 0;
    if (disposed) return;
    const shown = rows.filter((r) => passes(r, filter.value, Number(minLevel.value)));
    tbody.replaceChildren(...shown.map((r) => h("tr", { dataset: { number: String(r.number), level: r.level } },
      ...[String(r.number), r.time, r.level, r.source, r.title, r.message].map((t) => h("td", { text: t })))));
    count.textContent = `${shown.length} of ${rows.length} messages`;
    el.dataset.messages = String(rows.length);
    el.dataset.shown = String(shown.length);
  }
  const schedule = () => { if (!frame) frame = requestAnimationFrame(draw); };
  filter.addEventListener("input", schedule);
  minLevel.addEventListener("change", schedule);
  const add = (list) => { rows = mergeRows(rows, list.map((m) => messageRow(m, levels))); schedule(); };
  obj.eventlog_info.get().then(async (info) => {
    const w = newestWindow(info);
    if (!w || disposed) return;
    add(Array.from((await obj.getf_eventlog_messages(w.start, w.count)) ?? []));
    el.dataset.ready = "true";
  }).catch((e) => { errors.show(`messages: ${errorText(e)}`); el.dataset.ready = "true"; });
  if (has("eventlog_message_stream", "pipe")) {
    pipe = ctx.live.followPipe("eventlog_message_stream", { onPacket: (m) => add([m]), onError: errors.onMemberError("eventlog_message_stream") });
  }
  return { el, dispose() { disposed = true; pipe?.close(); if (frame) cancelAnimationFrame(frame); el.remove(); } };
}

export const eventLogPanel = { name: "eventlog", order: 30, types: EVENT_LOG_TYPES, create: createEventLogPanel };
