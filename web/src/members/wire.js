// A wire: followed while the device page is open (readonly and read-write wires), newest in-value
// shown and plotted; writable wires get an out-value editor. Peek reads the value without connecting.
// The connection is the device session's subscription's, shared with the panels that show the same
// wire (views/shared_wire.js): it is connected again by the subscription when the device or gateway
// closes it, and the card shows why it is down meanwhile.

import { h } from "../dom.js";
import { memberCard, valueInput } from "./card.js";
import { parseInput } from "../value_codec.js";
import { formatValue } from "../std/value_text.js";
import { memberText } from "../std/typed_text.js";
import { StreamDisplay } from "./stream_display.js";

export function wireView(ctx, member, _ObjectPanel, described) {
  const card = memberCard(ctx, member, described);
  const wire = ctx.obj[member.name];
  let display = null, follow = null;

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
    const input = valueInput(described.type, `${member.name} out value`);
    const send = async () => {
      try {
        const v = parseInput(described.type, input.read());
        if (follow?.connected) follow.setOutValue(v); else await wire.pokeOutValue(v);
        card.clearError();
      } catch (e) {
        card.showError(e);
      }
    };
    card.body.append(h("div", { class: "editor" }, input.el, h("button", { type: "button", text: "Send", onclick: send })));
  }
  // what the wire shows appears once it is connected (or brings a value)
  const shown = () => (display ??= new StreamDisplay(card.body, { type: described.type, view: ctx.view, label: member.name }));
  if (!member.writeonly) {
    follow = ctx.live.followWire(member.name, {
      onValue: (v) => shown().push(v),
      onError: (e) => {
        if (e) { card.showError(e); return; }
        card.clearError();
        shown();
      },
    });
  }
  return {
    el: card.el,
    dispose() {
      follow?.dispose();
      display?.dispose();
    },
  };
}
