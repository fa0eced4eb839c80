// The device card: who a standard device is, from its own `device_info` property
// (com.robotraconteur.device.DeviceInfo): name, UUID, manufacturer, model, serial number,
// description, device classes and the types it implements (with the object's own). Shown at the top
// of any object that has the property with the layout std/device_info.js reads.

import { h, errorText } from "../dom.js";
import { deviceInfoRows } from "../std/device_info.js";
import { describeMember } from "../views/context.js";

const DEVICE_INFO = "com.robotraconteur.device.DeviceInfo";

/** The object's device_info property when its type is a DeviceInfo of the layout the card reads. */
export function deviceInfoMember(obj, view) {
  const m = (obj?.$members || []).find((x) => x.kind === "property" && x.name === "device_info" && !x.writeonly);
  if (!m) return null;
  const d = describeMember(view, obj, m);
  return d?.type?.qualified === DEVICE_INFO && d.type.renderer ? m : null;
}

export function createDeviceCard(parent, ctx) {
  const obj = ctx.obj;
  const list = h("dl", { class: "device-card-rows" });
  const error = h("div", { class: "member-error", role: "alert", hidden: true });
  const el = h("section", { class: "panel device-card", dataset: { panel: "device-card" } },
    h("h3", { text: "Device" }), list, error);
  parent.append(el);
  let disposed = false;
  obj.device_info.get().then((info) => {
    if (disposed) return;
    const rows = deviceInfoRows(info, [obj.$type, ...(obj.$implements || [])]);
    list.replaceChildren(...rows.flatMap((r) => [
      h("dt", { text: r.label }), h("dd", { text: r.text, dataset: { row: r.key } }),
    ]));
    el.dataset.loaded = "true";
  }).catch((e) => {
    if (disposed) return;
    error.textContent = `device_info: ${errorText(e)}`;
    error.hidden = false;
  });
  return { el, dispose() { disposed = true; el.remove(); } };
}

export const deviceCardPanel = {
  name: "device-card",
  order: 10,
  applies: (obj, view) => !!deviceInfoMember(obj, view),
  create: createDeviceCard,
};
