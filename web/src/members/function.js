// A function: a form with one input per parameter (typed from the robdef), a Call button, and the
// result (or the device's error) shown in place as readable text (std/typed_text.js), standard
// pictures drawn (views/image_set.js). Generator functions list the items they yield.

import { h } from "../dom.js";
import { memberCard, valueInput } from "./card.js";
import { parseInput } from "../value_codec.js";
import { formatValue } from "../std/value_text.js";
import { asImage, drawImage } from "../image_view.js";
import { typedText } from "../std/typed_text.js";
import { hasImages, picturesOf, ImageSet } from "../views/image_set.js";

const MAX_GENERATOR_ITEMS = 100;

export function functionView(ctx, member, _ObjectPanel, described) {
  const card = memberCard(ctx, member, described);
  const type = described.type;
  const text = (v) => typedText(v, type, ctx.view?.text, 32);
  let images = null;
  const inputs = (member.params || []).map((p, i) => ({ param: p, type: described.params[i].type, input: valueInput(described.params[i].type, p.name) }));
  const result = h("output", { class: "result" });
  const canvas = h("canvas", { class: "image", hidden: true });
  let calls = 0;

  async function call(ev) {
    ev.preventDefault();
    let args;
    try {
      args = inputs.map(({ param, type: t, input }) => {
        try { return parseInput(t, input.read()); } catch (e) { throw new Error(`${param.name}: ${e.message}`); }
      });
    } catch (e) {
      card.showError(e);
      return;
    }
    button.disabled = true;
    result.textContent = "…";
    try {
      const r = await ctx.obj[member.name](...args);
      card.clearError();
      if (member.generator) await collect(r);
      else show(r);
      result.dataset.calls = String(++calls);
    } catch (e) {
      result.textContent = "";
      card.showError(e);
    } finally {
      button.disabled = false;
    }
  }

  function show(r) {
    result.textContent = member.type === "void" ? "done" : text(r);
    if (hasImages(type)) {
      images ??= new ImageSet(card.body, { context: ctx.view?.text, label: member.name });
      images.push(picturesOf(r, type));
      return;
    }
    const image = asImage(r);
    canvas.hidden = !image;
    if (image) drawImage(canvas, image);
  }

  async function collect(gen) {
    const items = [];
    result.textContent = "";
    for await (const item of gen) {
      items.push(item);
      result.append(h("div", { class: "generator-item", text: `${items.length}: ${text(item)}` }));
      if (items.length >= MAX_GENERATOR_ITEMS) {
        if (typeof gen.return === "function") await gen.return();
        break;
      }
    }
    if (!items.length) result.textContent = "(no items)";
  }

  const button = h("button", { type: "submit", text: "Call" });
  const form = h("form", { class: "function-form", onsubmit: call },
    ...inputs.map(({ param, input }) => h("label", { class: "param" }, h("span", { text: param.name }), input.el,
      h("small", { class: "param-type", text: param.type }))),
    button);
  card.body.append(form, result, canvas);
  return { el: card.el, dispose() { images?.dispose(); } };
}
