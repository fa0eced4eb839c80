// A memory: its length (dimensions for multidim memories), a read form (start, count; for multidim
// memories one number per dimension), the contents as a table of offsets and values (uint8 as hex),
// images drawn when the contents are one, and a write form.

import { h } from "../dom.js";
import { memberCard } from "./card.js";
import { parseInput } from "../value_codec.js";
import { formatValue } from "../std/value_text.js";
import { parseNumber } from "../std/rr_types.js";
import { asImage, drawImage } from "../image_view.js";
import { typedText } from "../std/typed_text.js";

const MAX_CELLS = 1024;
const PER_ROW = 16;

function numbers(text) {
  return String(text).split(/[\s,;]+/).filter(Boolean).map((s) => parseNumber("uint64", s)).map(Number);
}

export function memoryView(ctx, member, _ObjectPanel, described) {
  const card = memberCard(ctx, member, described);
  const item = described.type.element ?? null;  // pods and namedarrays read as their own text (UUIDs, times)
  const mem = ctx.obj[member.name];
  const t = described.type;
  const multidim = t.array === "multidim";
  const lengthOut = h("output", { class: "length" });
  const start = h("input", { type: "text", "aria-label": "start", value: multidim ? "0, 0, 0" : "0", spellcheck: "false" });
  const count = h("input", { type: "text", "aria-label": "count", value: multidim ? "" : "64", spellcheck: "false" });
  const table = h("div", { class: "memory-table" });
  const canvas = h("canvas", { class: "image", hidden: true });

  async function length() {
    try {
      const n = multidim ? await mem.dimensions() : await mem.length();
      lengthOut.textContent = Array.isArray(n) || ArrayBuffer.isView(n) ? Array.from(n).join(" × ") : String(n);
      if (multidim && !count.value && (Array.isArray(n) || ArrayBuffer.isView(n))) {
        count.value = Array.from(n).join(", ");
        start.value = Array.from(n, () => "0").join(", ");
      }
      card.clearError();
    } catch (e) {
      card.showError(e);
    }
  }

  async function read(ev) {
    ev.preventDefault();
    try {
      const s = numbers(start.value), c = numbers(count.value);
      const result = multidim ? await mem.read(s, c) : await mem.read(s[0], c[0]);
      card.clearError();
      show(result, s);
    } catch (e) {
      card.showError(e);
    }
  }

  function show(result, s) {
    const image = asImage(result);
    canvas.hidden = !image;
    if (image) drawImage(canvas, image);
    const values = multidim ? result.array : result;
    const shown = Array.from(values.slice(0, MAX_CELLS));
    const hex = t.base === "uint8";
    const perRow = shown.every((x) => typeof x === "number" || typeof x === "bigint") ? PER_ROW : 1;
    const cell = (x) => (hex ? x.toString(16).padStart(2, "0") : item && typeof x === "object" ? typedText(x, item, ctx.view?.text) : formatValue(x));
    const rows = [];
    for (let i = 0; i < shown.length; i += perRow) {
      const offset = multidim ? i : s[0] + i;
      rows.push(h("div", { class: "memory-row" }, h("span", { class: "offset", text: String(offset) }),
        h("span", { class: "cells", text: shown.slice(i, i + perRow).map(cell).join(" ") })));
    }
    const note = values.length > MAX_CELLS ? h("div", { class: "hint", text: `first ${MAX_CELLS} of ${values.length} values` }) : null;
    const dims = multidim ? h("div", { class: "hint", text: `dims ${Array.from(result.dims).join(" × ")} (column-major)` }) : null;
    table.replaceChildren(...[dims, ...rows, note].filter(Boolean));
    table.dataset.count = String(values.length);
  }

  const writeStart = h("input", { type: "text", "aria-label": "write start", value: multidim ? "0, 0, 0" : "0", spellcheck: "false" });
  const writeValues = h("input", { type: "text", "aria-label": "values to write", placeholder: multidim ? '{"dims": [...], "array": [...]}' : "1, 2, 3", spellcheck: "false" });
  async function write(ev) {
    ev.preventDefault();
    try {
      const s = numbers(writeStart.value);
      if (multidim) {
        const v = parseInput(t, writeValues.value);
        await mem.write(s, v);
      } else {
        await mem.write(s[0], parseInput(t, writeValues.value));
      }
      card.clearError();
    } catch (e) {
      card.showError(e);
    }
  }

  card.tools.append(h("button", { type: "button", class: "small", text: multidim ? "Dimensions" : "Length", onclick: length }));
  card.body.append(h("div", {}, h("span", { text: multidim ? "dimensions: " : "length: " }), lengthOut),
    h("form", { class: "memory-form", onsubmit: read },
      h("label", { class: "param" }, h("span", { text: "start" }), start),
      h("label", { class: "param" }, h("span", { text: "count" }), count), h("button", { type: "submit", text: "Read" })),
    table, canvas,
    member.readonly ? null : h("form", { class: "memory-form", onsubmit: write },
      h("label", { class: "param" }, h("span", { text: "start" }), writeStart),
      h("label", { class: "param" }, h("span", { text: "values" }), writeValues), h("button", { type: "submit", text: "Write" })));
  length();
  return { el: card.el, dispose() {} };
}
