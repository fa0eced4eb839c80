// The tool panel's status (panels/tool_panel.js): the newest tool_state as an operator reads it (time,
// position and command in millimetres with a bar from closed to open, the flags as coloured chips, the
// sensor values named and in their units from tool_info), a "stale" badge when no state came for 1 s,
// and the tool_info rows (type, capabilities, stroke, command range, actuation time, sensors, TCP).

import { h } from "../dom.js";
import { fieldText } from "../std/typed_text.js";
import { formatFlags } from "../std/enums.js";
import { isStale, STALE_MS } from "../robot/status.js";
import { toolFlagChips, mmText, openFraction, sensorRows, toolInfoRows } from "../tool/tool_state.js";

/**
 * The status parts of the panel's `tool`: `parts` { el (the panel), staleBadge, summary, infoRows };
 * `stateType` the tool_state wire's descriptor. Returns { draw() (the newest tool.state), drawInfo(),
 * markStale(), dispose() }.
 */
export function createToolStatus(tool, { el, staleBadge, summary, infoRows }, stateType, onStale) {
  const { view, enums } = tool;
  const timers = [];
  const bar = h("span", { class: "tool-bar", title: "closed ← → open" }, h("span", { class: "tool-bar-mark" }));

  function draw() {
    const s = tool.state;
    if (!s) return;
    const dd = (key, ...content) => h("dd", { dataset: { row: key } }, ...content);
    const rows = [];
    const tsField = stateType.fields.find((f) => f.name === "ts");
    if (tsField && s.ts !== undefined) rows.push(["time", dd("ts", fieldText(s, tsField, stateType, view?.text))]);
    const fraction = openFraction(s.position, tool.info);
    if (fraction !== null) bar.firstChild.style.left = `${(fraction * 100).toFixed(1)}%`;
    rows.push(["position", dd("position", h("span", { class: "tool-position", text: mmText(s.position) }), fraction !== null ? bar : null,
      fraction !== null ? h("span", { class: "hint", text: ` ${Math.round(fraction * 100)}% open` }) : null)]);
    if (s.command !== undefined) rows.push(["command", dd("command", mmText(s.command))]);
    const chips = toolFlagChips(enums.flag, s.tool_state_flags ?? 0);
    rows.push(["flags", dd("tool_state_flags", ...(chips.length ? chips.map((c) => h("span", { class: `chip chip-${c.tone}`, text: c.name, dataset: { flag: c.name } })) : ["none"]))]);
    for (const [i, r] of sensorRows(s, tool.info, enums.sensor).entries()) rows.push([r.label, dd(`sensor-${i}`, r.text)]);
    summary.replaceChildren(...rows.flatMap(([label, d]) => [h("dt", { text: label }), d]));
    el.dataset.flags = formatFlags(enums.flag, s.tool_state_flags ?? 0);
    el.dataset.position = String(s.position);
  }

  function drawInfo(infoType) {
    const info = tool.info;
    const rows = toolInfoRows(info, enums);
    const tcpField = infoType?.fields?.find((f) => f.name === "tcp");
    if (tcpField && info?.tcp) rows.push({ key: "tcp", label: "TCP", text: fieldText(info, tcpField, infoType, view?.text) });
    infoRows.replaceChildren(...rows.flatMap((r) => [h("dt", { text: r.label }), h("dd", { text: r.text, dataset: { row: r.key } })]));
    infoRows.hidden = !rows.length;
  }

  function markStale() {
    const stale = isStale(tool.lastStateMs, Date.now());
    if (String(stale) === el.dataset.stale) return;
    el.dataset.stale = String(stale);
    staleBadge.hidden = !stale;
    staleBadge.textContent = tool.lastStateMs ? `stale: no tool_state for over ${STALE_MS / 1000} s` : "no tool_state yet";
    onStale();
  }
  timers.push(setInterval(markStale, 250));

  return { draw, drawInfo, markStale, dispose() { for (const t of timers) clearInterval(t); } };
}
