// An objref: opens the object it refers to (by index for objref maps) and shows its members in a
// nested panel. Indices are offered from a property of the same object that maps the same key type
// (e.g. WebcamNames string{int32} next to Webcams Webcam{int32}). Open objects reopen after a reconnect.

import { h } from "../dom.js";
import { memberCard } from "./card.js";
import { parseNumber } from "../std/rr_types.js";
import { describeMember } from "../views/context.js";

export function objrefView(ctx, member, ObjectPanel, described) {
  const card = memberCard(ctx, member, described);
  const ref = ctx.obj[member.name];
  const t = described.type;
  const keyed = t.container === "int32" || t.container === "string";
  const memoryKey = `${ctx.path}${member.name}:open`;
  const opened = new Map(); // index text -> { panel, box }
  const index = h("input", { type: "text", "aria-label": `${member.name} index`, value: t.container === "int32" ? "0" : "", spellcheck: "false" });
  const suggestions = h("span", { class: "suggestions" });

  function remember() { ctx.memory.set(memoryKey, [...opened.keys()]); }

  async function open(key) {
    if (opened.has(key)) return;
    try {
      const idx = !keyed ? undefined : t.container === "int32" ? parseNumber("int32", key) : key;
      const child = keyed ? await ref.get(idx) : await ref.get();
      card.clearError();
      const label = keyed ? `${member.name}[${key}]` : member.name;
      const closeButton = h("button", { type: "button", class: "small", text: "Close", onclick: () => close(key) });
      const box = h("div", { class: "child-object", dataset: { path: `${ctx.path}${label}` } },
        h("div", { class: "child-title" }, h("strong", { text: label }), h("code", { text: ` ${child.$type ?? ""} ` }), closeButton));
      card.body.append(box);
      // the child's live members go through the session's subscription at its objref path (Webcams[0])
      const live = ctx.live.child(member.name, keyed ? key : undefined);
      const panel = new ObjectPanel(box, { ...ctx, obj: child, live, path: `${ctx.path}${label}.` });
      opened.set(key, { panel, box });
      remember();
    } catch (e) {
      card.showError(e);
    }
  }

  function close(key) {
    const o = opened.get(key);
    if (!o) return;
    o.panel.dispose();
    o.box.remove();
    opened.delete(key);
    remember();
  }

  const form = h("form", { class: "objref-form", onsubmit: (ev) => { ev.preventDefault(); open(keyed ? index.value.trim() : ""); } },
    keyed ? h("label", { class: "param" }, h("span", { text: "index" }), index) : null,
    h("button", { type: "submit", text: "Open" }), suggestions);
  card.body.append(form);

  // Offer the keys of a sibling map property with the same key type.
  if (keyed) {
    const sibling = (ctx.obj.$members || []).find((m) => m.kind === "property" && !m.writeonly && describeMember(ctx.view, ctx.obj, m)?.type.container === t.container);
    if (sibling) {
      ctx.obj[sibling.name].get().then((map) => {
        const entries = map instanceof Map ? [...map] : Object.entries(map || {});
        suggestions.replaceChildren(...entries.map(([k, v]) => h("button", {
          type: "button", class: "small suggestion", dataset: { index: String(k) }, text: `${k}: ${v}`,
          onclick: () => open(String(k)),
        })));
      }).catch(() => {});
    }
  }
  for (const key of ctx.memory.get(memoryKey) || []) open(key);
  return { el: card.el, dispose() { for (const k of [...opened.keys()]) { const o = opened.get(k); o.panel.dispose(); } opened.clear(); } };
}
