// com.robotraconteur.device.DeviceInfo (every standard device's `device_info` property) as the rows
// of a device card: name, UUID, manufacturer, model, serial number, description, device classes,
// implemented types. The renderer below states the layout the card reads; a device whose DeviceInfo
// has another layout gets no card (describe.js reports the mismatch) and the generic view shows it.

import { formatIdentifier } from "./identifier.js";
import { formatUuid, isNilUuid } from "./uuid.js";

const D = "com.robotraconteur.device";
const IDENTIFIER = "com.robotraconteur.identifier.Identifier";

/**
 * Rows [{ key, label, text }] of a DeviceInfo value, only those with something in them. `extraTypes`
 * (e.g. the object's own $type and $implements) are added to the implemented types.
 */
export function deviceInfoRows(info, extraTypes = []) {
  if (!info || typeof info !== "object") return [];
  const rows = [];
  const add = (key, label, text) => { if (text) rows.push({ key, label, text }); };
  const name = (id) => (id && typeof id === "object" && typeof id.name === "string" ? id.name : "");
  const idText = (id) => {
    if (!id || typeof id !== "object") return "";
    const t = formatIdentifier(id);
    return t === "(none)" ? "" : t;
  };
  add("name", "Name", name(info.device) || "(no name)");
  if (info.device?.uuid && !isNilUuid(info.device.uuid)) add("uuid", "UUID", formatUuid(info.device.uuid));
  add("manufacturer", "Manufacturer", idText(info.manufacturer));
  add("model", "Model", idText(info.model));
  add("serial", "Serial number", typeof info.serial_number === "string" ? info.serial_number : "");
  add("description", "Description", typeof info.user_description === "string" ? info.user_description : "");
  add("parent", "Parent device", idText(info.parent_device));
  const classes = Array.isArray(info.device_classes) ? info.device_classes : [];
  add("classes", "Device classes", classes.map((c) => {
    const n = name(c?.class_identifier);
    const subs = Array.isArray(c?.subclasses) && c.subclasses.length ? ` (${c.subclasses.join(", ")})` : "";
    return n ? `${n}${subs}` : "";
  }).filter(Boolean).join(", "));
  const types = [...new Set([...(Array.isArray(info.implemented_types) ? info.implemented_types : []), ...extraTypes])]
    .filter((t) => typeof t === "string" && t);
  add("types", "Implemented types", types.join(", "));
  return rows;
}

export const renderers = [
  {
    type: `${D}.DeviceInfo`,
    layout: {
      device: IDENTIFIER, manufacturer: IDENTIFIER, model: IDENTIFIER, serial_number: "string",
      user_description: "string", implemented_types: "string{list}",
    },
  },
];
