// A callback: the device calls the page. When answering is on, each call is logged and answered with
// the value in the editor (typed from the robdef's return type); when off, the call fails.

import { h } from "../dom.js";
import { memberCard, valueInput } from "./card.js";
import { formatValue, parseInput } from "../value_codec.js";

export function callbackView(ctx, member) {
  const card = memberCard(ctx, member);
  const box = h("input", { type: "checkbox" });
  const reply = member.type !== "void" ? valueInput(member.type, `${member.name} reply`, ctx.outline, ctx.scope) : null;
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
    const value = reply ? parseInput(member.type, reply.read(), ctx.outline, ctx.scope) : undefined;
    ctx.log.add("callback", ctx.path + member.name, `(${argText}) -> ${formatValue(value)}`);
    return value;
  };
  try {
    ctx.obj[member.name].set(handler);
  } catch (e) {
    card.showError(e);
  }
  return { el: card.el, dispose() {} };
}
