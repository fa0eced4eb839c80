// The members of one RR object (the device's root object, or one reached through an objref): first
// the panels its types call for (panels/: a device card, a camera panel, ...), then every member
// grouped by kind, each in its own card. Each member's type is described once here (views/context.js)
// and the descriptor handed to its view. ctx: { obj, outline, view, panels, definitions, log, memory, path }.

import { h } from "./dom.js";
import { propertyView } from "./members/property.js";
import { functionView } from "./members/function.js";
import { eventView } from "./members/event.js";
import { wireView } from "./members/wire.js";
import { pipeView } from "./members/pipe.js";
import { memoryView } from "./members/memory.js";
import { objrefView } from "./members/objref.js";
import { callbackView } from "./members/callback.js";
import { describeMember } from "./views/context.js";

// Live data first (wires, pipes), then what a person reads and changes most.
const SECTIONS = [
  ["wire", "Wires", wireView],
  ["pipe", "Pipes", pipeView],
  ["property", "Properties", propertyView],
  ["function", "Functions", functionView],
  ["objref", "Objects", objrefView],
  ["memory", "Memories", memoryView],
  ["event", "Events", eventView],
  ["callback", "Callbacks", callbackView],
];

export class ObjectPanel {
  constructor(parent, ctx) {
    this.views = [];
    const scope = ctx.outline.serviceOfObject(ctx.obj.$type);
    const full = { ...ctx, scope, linkType: (name) => ctx.definitions?.link(name, scope) ?? null };
    this.el = h("div", { class: "object-panel", dataset: { type: ctx.obj.$type ?? "" } });
    const panels = ctx.panels?.panelsFor(ctx.obj, ctx.view) ?? [];
    if (panels.length) {
      const box = h("div", { class: "type-panels" });
      this.el.append(box);
      for (const p of panels) {
        try {
          this.views.push(p.create(box, full));
        } catch (e) {
          box.append(h("div", { class: "member-error", text: `${p.name} panel: ${e?.message || e}` }));
        }
      }
    }
    const members = ctx.obj.$members || [];
    for (const [kind, title, view] of SECTIONS) {
      const list = members.filter((m) => m.kind === kind);
      if (!list.length) continue;
      const grid = h("div", { class: `member-grid grid-${kind}` });
      this.el.append(h("section", { class: "member-section", dataset: { section: kind } }, h("h3", { text: title }), grid));
      for (const m of list) {
        const v = view(full, m, ObjectPanel, describeMember(ctx.view, ctx.obj, m));
        grid.append(v.el);
        this.views.push(v);
      }
    }
    parent.append(this.el);
  }

  dispose() {
    for (const v of this.views) v.dispose();
    this.views = [];
    this.el.remove();
  }
}
