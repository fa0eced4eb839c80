// A pipe: connect an endpoint on request; packets are shown as they arrive (images drawn on a canvas,
// numbers plotted). The endpoint is the device session's subscription's (views/live_object.js
// followPipe): reconnected by it when the device or gateway closes it, and opened again after the page
// reconnects when it was open. Writable pipes can send.

import { h } from "../dom.js";
import { memberCard, valueInput } from "./card.js";
import { parseInput } from "../value_codec.js";
import { StreamDisplay } from "./stream_display.js";

export function pipeView(ctx, member, _ObjectPanel, described) {
  const card = memberCard(ctx, member, described);
  const memoryKey = `${ctx.path}${member.name}:open`;
  let pipe = null, display = null;

  const toggle = h("button", { type: "button", class: "small", text: "Connect", onclick: () => (pipe ? close(true) : open()) });
  card.tools.append(toggle);

  function open() {
    ctx.memory.set(memoryKey, true);
    toggle.textContent = "Disconnect";
    const shown = () => (display ??= new StreamDisplay(card.body, { type: described.type, view: ctx.view, label: member.name }));
    pipe = ctx.live.followPipe(member.name, {
      onPacket: (v) => shown().push(v),
      onOpen: (isOpen) => {
        if (!isOpen) { delete card.el.dataset.open; return; }
        shown();
        card.el.dataset.open = "true";
      },
      onError: (e) => (e ? card.showError(e) : card.clearError()),
    });
  }

  function close(byUser) {
    const p = pipe;
    pipe = null;
    if (byUser) ctx.memory.set(memoryKey, false);
    display?.dispose();
    display = null;
    toggle.textContent = "Connect";
    delete card.el.dataset.open;
    p?.close().catch(() => {});
  }

  if (!member.readonly) {
    const input = valueInput(described.type, `${member.name} packet`);
    const send = async () => {
      try {
        if (!pipe) throw new Error("Connect the pipe first");
        await pipe.send(parseInput(described.type, input.read()));
        card.clearError();
      } catch (e) {
        card.showError(e);
      }
    };
    card.body.append(h("div", { class: "editor" }, input.el, h("button", { type: "button", text: "Send", onclick: send })));
  }
  if (ctx.memory.get(memoryKey)) open();
  return { el: card.el, dispose() { close(false); } };
}
