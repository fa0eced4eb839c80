// The signal panel, for com.robotraconteur.signal Signal, SignalGroup and SignalDevice (I/O modules,
// PLC tags): every signal with its name, type, value live (its signal_value wire), units and access
// level, grouped as the device groups them (a SignalDevice's signal_group_info, each group's
// signal_info list, signal i being signals[i]). Writable signals (access level `all`) get a switch
// (digital) or a number input (others, checked against the signal's min and max before sending),
// shown only when the gateway lets the page's user write: for a Signal at the root its
// signal_command_vec (or signal_command) member; below the root the access answer names only the
// root's members, so the objref leading there (signal_groups, signals) decides, and the gateway checks
// the write itself. A write pokes signal_command_vec (double[]), else signal_command (a double[]
// varvalue); the value shown is always the device's own. Counts are bounded (signal_state.js).

import { h, errorText } from "../dom.js";
import { objectTypes } from "./registry.js";
import { allows } from "../robot/access.js";
import { errorLine, whenAccess } from "./panel_parts.js";
import { signalKind, signalText, signalCommand, MAX_SIGNALS, MAX_GROUPS } from "../signal/signal_state.js";

const S = "com.robotraconteur.signal";
export const SIGNAL_TYPES = [`${S}.Signal`, `${S}.SignalGroup`, `${S}.SignalDevice`];

const has = (obj, name, kind) => (obj?.$members || []).some((m) => m.name === name && m.kind === kind && !m.writeonly);
const hasWritable = (obj, name) => (obj?.$members || []).some((m) => m.name === name && m.kind === "wire" && !m.readonly);

export function createSignalPanel(parent, ctx) {
  const { obj, view } = ctx;
  const types = objectTypes(obj);
  const enumValues = (name) => view?.outline?.types?.get(name)?.values ?? [];
  const enums = { type: enumValues(`${S}.SignalType`), access: enumValues(`${S}.SignalAccessLevel`) };
  let disposed = false;
  const alive = () => !disposed;
  const errors = errorLine("signal-error", alive);
  const body = h("div", { class: "signal-groups" });
  const el = h("section", { class: "panel signal-panel", dataset: { panel: "signal", signals: "0" } }, h("h3", { text: "Signals" }), errors.el, body);
  parent.append(el);
  const follows = [];
  const rows = [];  // { kind, proxy, control(mayWrite) }

  /** A table of signals: `signals` [{ info, proxy, live }]. */
  function table(signals) {
    const tbody = h("tbody");
    const t = h("table", { class: "robot-joints signal-table" },
      h("thead", {}, h("tr", {}, ...["signal", "type", "value", "access", ""].map((x) => h("th", { text: x })))), tbody);
    for (const s of signals) {
      const kind = signalKind(s.info, enums);
      const value = h("td", { class: "signal-value" });
      const control = h("td", { class: "signal-control" });
      const name = kind.name || "(unnamed)";
      tbody.append(h("tr", { dataset: { signal: name, type: kind.type } },
        h("td", { text: name, title: kind.description }), h("td", { text: kind.type }), value, h("td", { text: kind.access }), control));
      const wire = has(s.proxy, "signal_value", "wire") ? "signal_value" : has(s.proxy, "signal_value_vec", "wire") ? "signal_value_vec" : null;
      let last = null;
      if (wire) {
        follows.push(s.live.followWire(wire, {
          onValue: (v) => {
            last = v;
            value.textContent = signalText(v, kind);
            value.dataset.value = value.textContent;
            const sw = control.querySelector("input[type=checkbox]");
            if (sw && document.activeElement !== sw) sw.checked = value.textContent === "on";
          },
          onError: errors.onMemberError(`${name}: ${wire}`),
        }));
      } else value.textContent = "(no value wire)";
      rows.push({ kind, proxy: s.proxy, control, get last() { return last; } });
    }
    el.dataset.signals = String(rows.length);
    return t;
  }

  async function write(row, input) {
    let cmd;
    try {
      cmd = signalCommand(row.kind, input);
    } catch (e) {
      errors.show(e.message);
      return;
    }
    try {
      if (hasWritable(row.proxy, "signal_command_vec")) await row.proxy.signal_command_vec.pokeOutValue(cmd);
      else await row.proxy.signal_command.pokeOutValue({ type: "double[]", value: cmd });
      errors.show(null);
      el.dataset.writes = String(Number(el.dataset.writes ?? 0) + 1);
    } catch (e) {
      errors.show(`${row.kind.name}: ${errorText(e)}`);
    }
  }

  function addControls(mayWrite) {
    for (const row of rows) {
      const canCommand = hasWritable(row.proxy, "signal_command_vec") || hasWritable(row.proxy, "signal_command");
      if (!row.kind.writable || !canCommand || !mayWrite) continue;
      if (row.kind.digital) {
        const sw = h("input", { type: "checkbox", name: `signal-${row.kind.name}`, "aria-label": `${row.kind.name} on` });
        sw.checked = row.control.parentElement.querySelector(".signal-value").textContent === "on";
        sw.addEventListener("change", () => write(row, sw.checked));
        row.control.replaceChildren(h("label", { class: "signal-switch" }, sw, " on"));
      } else {
        const input = h("input", { type: "number", name: `signal-${row.kind.name}`, step: "any", "aria-label": `${row.kind.name} value`,
          min: row.kind.min ?? undefined, max: row.kind.max ?? undefined });
        const set = h("button", { type: "button", class: "small", text: "Set", dataset: { action: "set" }, onclick: () => write(row, input.value) });
        row.control.replaceChildren(input, set);
      }
    }
  }

  /** The rows of one group object: its signal_info list, signal i at signals[i]. */
  async function groupSignals(group, live) {
    const infos = Array.from((await group.signal_info.get()) ?? []).slice(0, MAX_SIGNALS);
    return Promise.all(infos.map(async (info, i) => ({ info, proxy: await group.signals.get(i), live: live.child("signals", i) })));
  }

  let ready, objrefMember;
  if (types.has(`${S}.SignalDevice`) && has(obj, "signal_group_info", "property") && has(obj, "signal_groups", "objref")) {
    objrefMember = "signal_groups";
    ready = obj.signal_group_info.get().then(async (groups) => {
      for (const g of Array.from(groups ?? []).slice(0, MAX_GROUPS)) {
        const key = g?.signal_group_identifier?.name;
        if (!key || disposed) continue;
        const group = await obj.signal_groups.get(key);
        const signals = await groupSignals(group, ctx.live.child("signal_groups", key));
        if (disposed) return;
        body.append(h("div", { class: "signal-group", dataset: { group: key } },
          h("h4", { text: g.description ? `${key}: ${g.description}` : key }), table(signals)));
      }
    });
  } else if (types.has(`${S}.SignalGroup`) && has(obj, "signal_info", "property") && has(obj, "signals", "objref")) {
    objrefMember = "signals";
    ready = groupSignals(obj, ctx.live).then((signals) => { if (!disposed) body.append(table(signals)); });
  } else if (types.has(`${S}.Signal`) && has(obj, "signal_info", "property")) {
    ready = obj.signal_info.get().then((info) => { if (!disposed) body.append(table([{ info, proxy: obj, live: ctx.live }])); });
  } else {
    el.dataset.fallback = "true";
    body.append(h("div", { class: "hint", text: "this device lacks the standard signal members (signal_info, signal_groups): its members are shown below" }));
    return { el, dispose() { el.remove(); } };
  }
  const loaded = ready.catch((e) => errors.show(`signals: ${errorText(e)}`));
  whenAccess(ctx, el, loaded, alive, (access) => {
    const mayWrite = objrefMember ? allows(access, objrefMember, "write")
      : allows(access, hasWritable(obj, "signal_command_vec") ? "signal_command_vec" : "signal_command", "write");
    addControls(mayWrite);
    el.dataset.ready = "true";
  }, (text) => { errors.show(text); el.dataset.ready = "true"; });

  return { el, dispose() { disposed = true; for (const f of follows) f.dispose(); el.remove(); } };
}

export const signalPanel = { name: "signal", order: 20, types: SIGNAL_TYPES, create: createSignalPanel };
