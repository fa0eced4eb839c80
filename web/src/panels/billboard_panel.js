// The billboard panel, for com.robotraconteur.device.BillboardDevice: a device that is only its
// device_info (a label, a sign, a note on the bench), whose text is its user_description, shown large,
// with the device's name. Read once; the device card beside it has the rest of device_info.

import { h, errorText } from "../dom.js";
import { errorLine } from "./panel_parts.js";

export const BILLBOARD = "com.robotraconteur.device.BillboardDevice";

export function createBillboardPanel(parent, ctx) {
  const { obj } = ctx;
  let disposed = false;
  const errors = errorLine("billboard-error", () => !disposed);
  const text = h("div", { class: "billboard-text", style: "font-size: 1.6em; white-space: pre-wrap; padding: 8px 0" });
  const name = h("div", { class: "hint billboard-name" });
  const el = h("section", { class: "panel billboard-panel", dataset: { panel: "billboard" } }, h("h3", { text: "Billboard" }), errors.el, text, name);
  parent.append(el);
  if (!(obj.$members || []).some((m) => m.name === "device_info" && m.kind === "property")) {
    el.dataset.fallback = "true";
    text.textContent = "";
    name.textContent = "this billboard has no device_info property: its members are shown below";
    return { el, dispose() { el.remove(); } };
  }
  obj.device_info.get().then((i) => {
    if (disposed) return;
    text.textContent = typeof i?.user_description === "string" && i.user_description ? i.user_description : "(no text: user_description is empty)";
    name.textContent = i?.device?.name ? `${i.device.name}` : "";
    el.dataset.ready = "true";
  }, (e) => errors.show(`device_info: ${errorText(e)}`));
  return { el, dispose() { disposed = true; el.remove(); } };
}

export const billboardPanel = { name: "billboard", order: 15, types: [BILLBOARD], create: createBillboardPanel };
