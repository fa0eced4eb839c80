// An event: subscribed while the device page is open; each firing goes to the event log, its
// arguments as readable text (std/typed_text.js) typed by the event's parameters.

import { h } from "../dom.js";
import { memberCard } from "./card.js";
import { formatValue } from "../std/value_text.js";
import { typedText } from "../std/typed_text.js";

export function eventView(ctx, member, _ObjectPanel, described) {
  const card = memberCard(ctx, member, described);
  const params = described.params.map((p) => p.type);
  const text = (a, i) => (params[i] ? typedText(a, params[i], ctx.view?.text) : formatValue(a));
  const count = h("output", { class: "count", text: "0" });
  card.body.append(h("div", {}, "received: ", count));
  let n = 0, off = null;
  try {
    // through the device session's subscription (views/live_object.js): subscribed again after a reconnect
    off = ctx.live.onEvent(member.name, (...args) => {
      count.textContent = String(++n);
      ctx.log.add("event", ctx.path + member.name, args.length ? args.map(text).join(", ") : "(no arguments)");
    });
  } catch (e) {
    card.showError(e);
  }
  return { el: card.el, dispose() { if (typeof off === "function") off(); } };
}
