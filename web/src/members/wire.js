// A wire: connected while the device page is open (readonly and read-write wires), newest in-value
// shown and plotted; writable wires get an out-value editor. Peek reads the value without connecting.
// A wire connection that closes while the page is open is connected again after REOPEN_MS. The
// connection is shared with the panels that show the same wire (views/shared_wire.js).

import { h } from "../dom.js";
import { memberCard, valueInput } from "./card.js";
import { formatValue, parseInput } from "../value_codec.js";
import { parseType } from "../rr_types.js";
import { memberText } from "../std/typed_text.js";
import { StreamDisplay } from "./stream_display.js";
import { connectShared } from "../views/shared_wire.js";

const REOPEN_MS = 2000;

export function wireView(ctx, member, _ObjectPanel, described = null) {
  const card = memberCard(ctx, member, described);
  const wire = ctx.obj[member.name];
  const qualified = ctx.outline.typeOf(parseType(member.type).base, ctx.scope)?.qualified ?? null;
  let conn = null, display = null, disposed = false, reopen = 0;

  async function open() {
    try {
      conn = await connectShared(ctx.obj, member.name);
      if (disposed) { await conn.close(); return; }
      card.clearError();
      display ??= new StreamDisplay(card.body, { qualifiedType: qualified, type: described?.type, view: ctx.view, label: member.name });
      conn.onChange((v) => display.push(v));
      conn.onClose((err) => {
        conn = null;
        if (disposed) return;
        card.showError(err ?? new Error("wire connection closed"));
        reopen = setTimeout(open, REOPEN_MS);
      });
      try {
        const v = conn.inValue;
        if (v !== undefined) display.push(v);
      } catch {
        // no value received yet: the first onChange brings it
      }
    } catch (e) {
      if (disposed) return;
      card.showError(e);
      reopen = setTimeout(open, REOPEN_MS);
    }
  }

  if (!member.writeonly) {
    card.tools.append(h("button", {
      type: "button", class: "small", text: "Peek", onclick: async () => {
        try {
          const v = await wire.peekInValue();
          peekOut.textContent = described ? memberText(v, described, ctx.view?.text) : formatValue(v);
          card.clearError();
        } catch (e) { card.showError(e); }
      },
    }));
  }
  const peekOut = h("output", { class: "peek" });
  card.body.append(peekOut);
  if (!member.readonly) {
    const input = valueInput(member.type, `${member.name} out value`, ctx.outline, ctx.scope);
    const send = async () => {
      try {
        const v = parseInput(member.type, input.read(), ctx.outline, ctx.scope);
        if (conn) conn.outValue = v; else await wire.pokeOutValue(v);
        card.clearError();
      } catch (e) {
        card.showError(e);
      }
    };
    card.body.append(h("div", { class: "editor" }, input.el, h("button", { type: "button", text: "Send", onclick: send })));
  }
  if (!member.writeonly) open();
  return {
    el: card.el,
    dispose() {
      disposed = true;
      clearTimeout(reopen);
      display?.dispose();
      if (conn) conn.close().catch(() => {});
    },
  };
}
