// A property: its value (read on open) as readable text (std/typed_text.js: UUIDs, times, poses,
// enums and flags by name), standard pictures drawn (views/image_set.js), an editor typed from the
// robdef for writable properties, and for numeric properties a live plot fed by polling get().

import { h } from "../dom.js";
import { memberCard, valueInput } from "./card.js";
import { parseInput, editorText } from "../value_codec.js";
import { formatValue } from "../std/value_text.js";
import { isPlottable } from "../std/rr_types.js";
import { LivePlot } from "../live_plot.js";
import { memberText } from "../std/typed_text.js";
import { typedNumericFields } from "../std/plot_fields.js";
import { hasImages, picturesOf, ImageSet } from "../views/image_set.js";

const POLL_MS = 250;

export function propertyView(ctx, member, _ObjectPanel, described) {
  const card = memberCard(ctx, member, described);
  const prop = ctx.obj[member.name];
  const out = h("output", { class: "value" });
  let plot = null, timer = 0, inFlight = false, disposed = false, reads = 0, images = null;

  // pictures: their bytes are not written out as editor text (megabytes), unless the property is writable
  const pictures = hasImages(described.type);
  const wantsText = !pictures || !member.readonly;

  function show(v, text) {
    if (wantsText) out.dataset.value = text;
    out.textContent = memberText(v, described, ctx.view?.text, 32);
    if (pictures) {
      images ??= new ImageSet(card.body, { context: ctx.view?.text, label: member.name });
      images.push(picturesOf(v, described.type));
    }
  }

  function plotPairs(v) {
    return typedNumericFields(v, described.type, member.name).map(([n, x, hide, label]) => [n, x, hide || !!described.flags, label]);
  }

  async function read() {
    inFlight = true;
    try {
      const v = await prop.get();
      if (disposed) return undefined;
      const text = wantsText ? editorText(described.type, v) : "";  // before the pictures' bytes go to their decoder
      const pairs = plot ? plotPairs(v) : null;
      show(v, text);
      if (pairs) plot?.push(pairs);
      out.dataset.reads = String(++reads);
      card.clearError();
      return { v, text };
    } catch (e) {
      if (!disposed) card.showError(e);
      return undefined;
    } finally {
      inFlight = false;
    }
  }

  if (!member.writeonly) {
    card.tools.append(h("button", { type: "button", class: "small", text: "Read", onclick: read }));
    card.body.append(out);
  }
  let input = null;
  if (!member.readonly) {
    input = valueInput(described.type, `${member.name} value`);
    const set = async () => {
      try {
        const v = parseInput(described.type, input.read());
        await prop.set(v);
        card.clearError();
        if (!member.writeonly) await read();
      } catch (e) {
        card.showError(e);
      }
    };
    card.body.append(h("div", { class: "editor" }, input.el, h("button", { type: "button", text: "Set", onclick: set })));
  }

  const memoryKey = `${ctx.path}${member.name}:plot`;
  function setPlotting(on) {
    ctx.memory.set(memoryKey, on);
    if (on && !plot) {
      plot = new LivePlot(card.body, { height: 110 });
      timer = setInterval(() => { if (!inFlight) read(); }, POLL_MS);
    } else if (!on && plot) {
      clearInterval(timer);
      plot.dispose();
      plot = null;
    }
  }
  if (isPlottable(described.type) && !member.writeonly) {
    const on = ctx.memory.get(memoryKey) ?? Boolean(member.readonly);
    const box = h("input", { type: "checkbox", checked: on, onchange: () => setPlotting(box.checked) });
    card.tools.prepend(h("label", { class: "toggle" }, box, "plot"));
    setPlotting(on);
  }

  if (!member.writeonly) read().then((r) => { if (input && r !== undefined) input.write(r.text); });
  return {
    el: card.el,
    dispose() { disposed = true; clearInterval(timer); plot?.dispose(); images?.dispose(); },
  };
}
