// A callback: the device calls the page. When answering is on, each call is logged and answered with
// the value in the editor (typed from the robdef's return type); when off, the call fails.

import { h } from "../dom.js";
import { memberCard, valueInput } from "./card.js";
import { parseInput } from "../value_codec.js";
import { formatValue } from "../std/value_text.js";

export function callbackView(ctx, member, _ObjectPanel, described) {
  const card = memberCard(ctx, member, described);
  const box = h("input", { type: "checkbox" });
  const reply = member.type !== "void" ? valueInput(described.type, `${member.name} reply`) : null;
  const count = h("output", { class: "count", text: "0" });
  let n = 0;
  card.body.append(h("label", { class: "toggle" }, box, "answer calls"),
    reply ? h("label", { class: "param" }, h("span", { text: "reply" }), reply.el) : null,
    h("div", {}, "calls: ", count));
  const handler = (...args) => {
    count.textContent = String(++n);
    const argText = args.map((a) => formatValue(a)).join(", ");
    if (!box.checked) {
      ctx.log.add("callback", ctx.path + member.name, `(${argText}) refused: answering is off`);
      throw new Error("The dashboard is not answering this callback");
    }
    const value = reply ? parseInput(described.type, reply.read()) : undefined;
    ctx.log.add("callback", ctx.path + member.name, `(${argText}) -> ${formatValue(value)}`);
    return value;
  };
  // answered through the device session's subscription (views/live_object.js), set again after a reconnect
  let clear = null;
  try {
    clear = ctx.live.setCallback(member.name, handler);
  } catch (e) {
    card.showError(e);
  }
  return { el: card.el, dispose() { clear?.(); } };
}
