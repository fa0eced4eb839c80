// A pipe: connect an endpoint on request; packets are shown as they arrive (images drawn on a canvas,
// numbers plotted). An endpoint that the device or gateway closes is reopened after REOPEN_MS, and an
// open endpoint is reopened after the page reconnects. Writable pipes can send.

import { h } from "../dom.js";
import { memberCard, valueInput } from "./card.js";
import { parseInput } from "../value_codec.js";
import { parseType } from "../rr_types.js";
import { StreamDisplay } from "./stream_display.js";

const REOPEN_MS = 2000;

export function pipeView(ctx, member, _ObjectPanel, described = null) {
  const card = memberCard(ctx, member, described);
  const pipe = ctx.obj[member.name];
  const qualified = ctx.outline.typeOf(parseType(member.type).base, ctx.scope)?.qualified ?? null;
  const memoryKey = `${ctx.path}${member.name}:open`;
  let ep = null, display = null, disposed = false, reopen = 0;

  const toggle = h("button", { type: "button", class: "small", text: "Connect", onclick: () => (ep ? close(true) : open()) });
  card.tools.append(toggle);

  async function open() {
    toggle.disabled = true;
    try {
      ep = await pipe.connect(-1);
      if (disposed) { await ep.close(); return; }
      ctx.memory.set(memoryKey, true);
      card.clearError();
      display = new StreamDisplay(card.body, { qualifiedType: qualified, type: described?.type, view: ctx.view, label: member.name });
      ep.onPacket((v) => display.push(v));
      const mine = ep;
      ep.onClose((err) => {
        if (disposed || ep !== mine) return; // closed by us
        close(false);
        card.showError(err ?? new Error("pipe endpoint closed"));
        reopen = setTimeout(open, REOPEN_MS);
      });
      toggle.textContent = "Disconnect";
      card.el.dataset.open = "true";
    } catch (e) {
      ep = null;
      if (!disposed) {
        card.showError(e);
        if (ctx.memory.get(memoryKey)) reopen = setTimeout(open, REOPEN_MS);
      }
    } finally {
      toggle.disabled = false;
    }
  }

  async function close(byUser) {
    clearTimeout(reopen);
    const e = ep;
    ep = null;
    if (byUser) ctx.memory.set(memoryKey, false);
    display?.dispose();
    display = null;
    toggle.textContent = "Connect";
    delete card.el.dataset.open;
    if (e) await e.close().catch(() => {});
  }

  if (!member.readonly) {
    const input = valueInput(member.type, `${member.name} packet`, ctx.outline, ctx.scope);
    const send = async () => {
      try {
        if (!ep) throw new Error("Connect the pipe first");
        await ep.send(parseInput(member.type, input.read(), ctx.outline, ctx.scope));
        card.clearError();
      } catch (e) {
        card.showError(e);
      }
    };
    card.body.append(h("div", { class: "editor" }, input.el, h("button", { type: "button", text: "Send", onclick: send })));
  }
  if (ctx.memory.get(memoryKey)) open();
  return { el: card.el, dispose() { disposed = true; close(false); } };
}
