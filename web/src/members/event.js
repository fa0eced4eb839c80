// An event: subscribed while the device page is open; each firing goes to the event log.

import { h } from "../dom.js";
import { memberCard } from "./card.js";
import { formatValue } from "../value_codec.js";

export function eventView(ctx, member) {
  const card = memberCard(ctx, member);
  const count = h("output", { class: "count", text: "0" });
  card.body.append(h("div", {}, "received: ", count));
  let n = 0, off = null;
  try {
    off = ctx.obj[member.name].on((...args) => {
      count.textContent = String(++n);
      ctx.log.add("event", ctx.path + member.name, args.length ? args.map((a) => formatValue(a)).join(", ") : "(no arguments)");
    });
  } catch (e) {
    card.showError(e);
  }
  return { el: card.el, dispose() { if (typeof off === "function") off(); } };
}
