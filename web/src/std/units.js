// Units of numeric fields, where the structure names them in a sibling field: SensorData's `data` in
// `data_units` (com.robotraconteur.units.SIUnit{list}), AdvancedRobotState's `joint_position` in
// `joint_position_units` (uint8[] of JointPositionUnits values), ToolInfo's `sensor_min` in
// `sensor_units`. The sibling of field F is F_units, or for F = P_min, P_max, P_command or
// P_resolution, P_units.

import { findNamed } from "./describe.js";
import { isNumericBase } from "./rr_types.js";

/** The text of an SIUnit value ({display_units, encoded_units}): display_units, else encoded_units. */
export function siUnitText(u) {
  if (!u || typeof u !== "object") return null;
  return u.display_units || u.encoded_units || null;
}

const camel = (s) => s.split("_").filter(Boolean).map((w) => w[0].toUpperCase() + w.slice(1)).join("");

/** The name of the field of `owner` (outline entry) that holds the units of field `name`, or null. */
export function unitsFieldFor(owner, name) {
  const names = new Set((owner?.fields || []).map((f) => f.name));
  const n = String(name);
  if (/(^|_)(units|flags|capabilities)$/.test(n)) return null;
  const candidates = [`${n}_units`];
  const qualified = /^(.+)_(min|max|command|resolution)$/.exec(n);
  if (qualified) candidates.push(`${qualified[1]}_units`);
  return candidates.find((c) => names.has(c)) ?? null;
}

/**
 * Field annotator for TypeDescriber: { units: { field, enumValues } } on numeric fields whose units a
 * sibling names; enumValues for siblings of enum codes in an integer array, found by the sibling's
 * name in CamelCase (joint_position_units → JointPositionUnits). Reads the fields' descriptors
 * (`field.descriptor`, `fieldTypes`), not their type text.
 */
export function unitsAnnotator(owner, field, outline, fieldTypes) {
  const t = field.descriptor;
  if (!t || t.container || !isNumericBase(t.base) || t.base === "bool") return null;
  const sibling = unitsFieldFor(owner, field.name);
  if (!sibling) return null;
  const siblingType = fieldTypes?.get(sibling);
  let enumValues = null;
  if (siblingType && isNumericBase(siblingType.base)) {
    const e = findNamed(outline, camel(sibling), owner.service);
    if (e?.kind === "enum") enumValues = e.values;
  }
  return { units: { field: sibling, enumValues } };
}

/**
 * The unit texts of field `field` (a descriptor field with `units`) in structure value `owner`: one
 * per item of the sibling (SIUnit → display text, enum code → name, string as is), or null.
 * @param {object} owner  the structure's value
 * @param {object} field  the field ({name, units: {field, enumValues}})
 * @param {object} [siblingField]  the sibling's descriptor field (for enum{list} names)
 */
export function unitsOf(owner, field, siblingField) {
  const list = owner?.[field?.units?.field];
  if (!list || typeof list.length !== "number" || !list.length) return null;
  const names = field.units.enumValues || siblingField?.type?.element?.enumValues;
  return Array.from(list, (u) => {
    if (typeof u === "string") return u;
    if (typeof u === "number" || typeof u === "bigint") {
      return names?.find((e) => e.value === Number(u))?.name ?? String(u);
    }
    return siUnitText(u) ?? "?";
  });
}

export const renderers = [
  {
    type: "com.robotraconteur.units.SIUnit", layout: { display_units: "string", encoded_units: "string" },
    text: (v) => siUnitText(v) ?? "(no units)",
  },
];
