// The resource panel, for com.robotraconteur.resource ResourceReadOnlyStorage, ResourceStorage and
// ResourceStorageDevice: the stored resources as a list per bucket (resource_bucket_info: the bucket's
// name, description and keys), each with Info (resource_get_info: size, times, description) and Download
// (resource_get: the parts put together, at most 64 MiB, saved by the browser under the key's name).
// Read-only: nothing is added, changed or deleted from the page. Storage without
// resource_bucket_info gets one line saying so and the generic view below.

import { h, errorText } from "../dom.js";
import { errorLine } from "./panel_parts.js";
import { timeParts, isoTime } from "../std/datetime.js";
import { assembleParts, sizeText, MAX_RESOURCE_BYTES } from "../resource/resource.js";

const R = "com.robotraconteur.resource";
export const RESOURCE_TYPES = [`${R}.ResourceReadOnlyStorage`, `${R}.ResourceStorage`, `${R}.device.ResourceStorageDevice`];
const MAX_KEYS = 500;

export function createResourcePanel(parent, ctx) {
  const { obj } = ctx;
  const has = (name, kind) => (obj.$members || []).some((m) => m.name === name && m.kind === kind);
  let disposed = false;
  const errors = errorLine("resource-error", () => !disposed);
  const body = h("div", { class: "resource-buckets" });
  const el = h("section", { class: "panel resource-panel", dataset: { panel: "resource" } }, h("h3", { text: "Resources" }), errors.el, body);
  parent.append(el);
  if (!has("resource_bucket_info", "property")) {
    el.dataset.fallback = "true";
    body.append(h("div", { class: "hint", text: "this storage has no resource_bucket_info property: its members are shown below" }));
    return { el, dispose() { el.remove(); } };
  }
  const when = (t) => { const p = timeParts(Array.isArray(t) ? t[0] : t); return p && p.seconds !== 0n ? isoTime(p) : ""; };

  async function info(id, out) {
    try {
      const i = await obj.resource_get_info(id);
      out.textContent = [sizeText(i.total_size), when(i.modified) && `modified ${when(i.modified)}`, i.description].filter(Boolean).join(", ");
      out.dataset.size = String(i.total_size);
    } catch (e) { errors.show(`resource_get_info ${id.key}: ${errorText(e)}`); }
  }
  async function download(id, button, out) {
    button.disabled = true;
    try {
      const gen = await obj.resource_get(id);
      const parts = [];
      let bytes = 0;
      for await (const p of gen) {
        parts.push(p);
        bytes += p.data?.length ?? 0;
        if (bytes > MAX_RESOURCE_BYTES) { await gen.abort().catch(() => {}); throw new Error(`more than ${sizeText(MAX_RESOURCE_BYTES)}: not downloaded`); }
      }
      const data = assembleParts(parts);
      out.textContent = `${sizeText(data.length)} downloaded`;
      out.dataset.bytes = String(data.length);
      const url = URL.createObjectURL(new Blob([data]));
      const a = h("a", { href: url, download: id.key.split("/").pop() || "resource" });
      document.body.append(a);
      a.click();
      a.remove();
      setTimeout(() => URL.revokeObjectURL(url), 60000);
      errors.show(null);
    } catch (e) {
      errors.show(`resource_get ${id.key}: ${errorText(e)}`);
    } finally {
      button.disabled = false;
    }
  }

  obj.resource_bucket_info.get().then((buckets) => {
    if (disposed) return;
    for (const b of Array.from(buckets ?? [])) {
      const name = b?.identifier?.name ?? "";
      const keys = Array.from(b?.keys ?? []).slice(0, MAX_KEYS);
      const list = h("ul", { class: "resource-keys" }, ...keys.map((key) => {
        const id = { bucket: b.identifier, key };
        const out = h("span", { class: "hint resource-out" });
        const buttons = [];
        if (has("resource_get_info", "function")) buttons.push(h("button", { type: "button", class: "small", text: "Info", dataset: { action: "info" }, onclick: () => info(id, out) }));
        if (has("resource_get", "function")) {
          const d = h("button", { type: "button", class: "small", text: "Download", dataset: { action: "download" } });
          d.addEventListener("click", () => download(id, d, out));
          buttons.push(d);
        }
        return h("li", { dataset: { key } }, h("code", { text: key }), " ", ...buttons, " ", out);
      }));
      body.append(h("div", { class: "resource-bucket", dataset: { bucket: name } },
        h("h4", { text: b.description ? `${name}: ${b.description}` : name }), list));
    }
    el.dataset.ready = "true";
  }, (e) => { errors.show(`resource_bucket_info: ${errorText(e)}`); el.dataset.ready = "true"; });
  return { el, dispose() { disposed = true; el.remove(); } };
}

export const resourcePanel = { name: "resource", order: 20, types: RESOURCE_TYPES, create: createResourcePanel };
