// The pictures inside a value, by its type descriptor (std/describe.js): the value itself when its
// type has a renderer with a picture hook (`image` or `compressed`: the standard Image and
// CompressedImage, or a page's own) that the device's definitions matched, or each item of an array,
// list or map of them (MultiCamera's Image{int32}), each drawn by its renderer in a FrameView of its
// own (keyed by index or map key, up to MAX_PICTURES).

import { h } from "../dom.js";
import { FrameView } from "./frame_view.js";

export const MAX_PICTURES = 8;

/** "image", "compressed" or null: how a single value of descriptor `d` is drawn. */
export function imageKind(d) {
  if (!d || d.array || d.container) return null;
  if (d.renderer?.image) return "image";
  if (d.renderer?.compressed) return "compressed";
  return null;
}

/** True when values of `d` hold standard pictures (themselves or as items). */
export function hasImages(d) {
  return !!(imageKind(d) || ((d?.array === "vector" || d?.container) && imageKind(d.element)));
}

/**
 * [[key, item, kind, renderer]] of the pictures in `value` typed by `d`: [["", value, kind, renderer]]
 * for a picture, the items of an array or map of pictures (null items skipped), else [].
 */
export function picturesOf(value, d, max = MAX_PICTURES) {
  if (value === null || value === undefined) return [];
  const own = imageKind(d);
  if (own) return [["", value, own, d.renderer]];
  const kind = (d?.array === "vector" || d?.container) ? imageKind(d.element) : null;
  if (!kind) return [];
  const renderer = d.element.renderer;
  let entries;
  if (value instanceof Map) entries = [...value].sort(([a], [b]) => (a < b ? -1 : a > b ? 1 : 0));
  else if (Array.isArray(value)) entries = value.map((x, i) => [i, x]);
  else if (typeof value === "object") entries = Object.entries(value);
  else return [];
  return entries.filter(([, x]) => x && typeof x === "object").slice(0, max).map(([k, x]) => [String(k), x, kind, renderer]);
}

/** FrameViews by key, made as keys first appear. */
export class ImageSet {
  /** @param {HTMLElement} parent @param {object} opts  for FrameView (context: the renderers' context) and label */
  constructor(parent, opts = {}) {
    this.opts = opts;
    this.el = h("div", { class: "image-set" });
    parent.append(this.el);
    this.views = new Map();
  }

  /** Pushes each [key, value, kind, renderer] (picturesOf) to its FrameView. */
  push(pictures) {
    for (const [key, value, , renderer] of pictures) {
      let view = this.views.get(key);
      if (!view) {
        const box = h("div", { class: "image-item", dataset: { key } }, key === "" ? null : h("div", { class: "image-key", text: `[${key}]` }));
        this.el.append(box);
        view = new FrameView(box, { ...this.opts, renderer, label: key === "" ? this.opts.label : `${this.opts.label || "image"} [${key}]` });
        view.box = box;
        this.views.set(key, view);
      }
      view.push(value);
    }
  }

  dispose() {
    for (const v of this.views.values()) v.dispose();
    this.views.clear();
    this.el.remove();
  }
}
